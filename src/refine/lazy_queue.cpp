// The collapse in strict order of cost: a priority queue with lazy updates (Garland &
// Heckbert 1997 §4), the last driver of collapse_state().
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "common/flat_hash_map.hpp"
#include "common/huge_pages.hpp"
#include "refine/collapse_queue.hpp"
#include "refine/edge_collapse.hpp"
#include "refine/small_lists.hpp"
#include "runtime/progress_phase.hpp"

namespace oocsimp {

namespace {

// The driver of one run: a heap of candidates, each checked against the state when
// taken. An entry is stale when the cost of its edge has changed since it was pushed
// (an end moved); a rejected edge is pushed again when a collapse changes its
// neighbourhood, so the collapse taken is always the cheapest valid one, as if every
// edge were re-evaluated after every collapse.
class LazyQueue {
 public:
  LazyQueue(CollapseState& state, const CollapseSettings& settings, CollapseStats* stats, ProgressPhase* progress)
      : state_(state), settings_(settings), stats_(stats), progress_(progress), unblamed_(state.vertex_count()) {}

  void run() {
    fill();
    std::vector<QueueEntry> deferred;  // inner edges when one triangle is left to remove
    while (state_.triangle_count() > settings_.target_triangles) {
      if (heap_.empty()) {
        if (settings_.exact_count && !take_deferred(deferred)) stats_->stuck = true;
        return;
      }
      const QueueEntry e = heap_.pop();
      if (!state_.alive(e.a) || !state_.alive(e.b)) continue;
      const CollapseState::Candidate c = state_.evaluate(e.a, e.b);
      if (!same_bits(c.cost, e.cost)) continue;  // stale
      std::uint32_t blamed = CollapseState::kNoFace;
      if (!state_.valid(c, &blamed)) {
        reject(e.a, e.b, blamed);
        continue;
      }
      // A collapse removes its edge's faces: 2 inside, 1 on a boundary, more in a
      // tangle. One that would go below the target waits (a closed surface's count
      // is even: with one triangle to go only a boundary edge meets it).
      if (settings_.exact_count &&
          state_.triangle_count() - settings_.target_triangles < std::uint64_t(state_.faces_removed(c))) {
        deferred.push_back(e);
        continue;
      }
      if (!take(c)) return;
    }
  }

 private:
  // Every edge, its cost computed in parallel (each independent of the others).
  // Room is kept for the pushes of the collapses to come (about a dozen each, the
  // edges around the moved vertex), so the heap seldom regrows.
  void fill() {
    const auto edges = state_.edges();
    const std::uint64_t collapses =
        (state_.triangle_count() - std::min(state_.triangle_count(), settings_.target_triangles)) / 2;
    std::vector<QueueEntry> entries;
    reserve_huge(&entries, std::size_t(std::min<std::uint64_t>(4 * edges.size(), edges.size() + 12 * collapses)));
    entries.resize(edges.size());
    tbb::parallel_for(std::size_t(0), edges.size(), [&](std::size_t i) {
      const CollapseState::Candidate c = state_.evaluate(edges[i].first, edges[i].second);
      entries[i] = {c.cost, c.a, c.b};
    });
    heap_.assign(std::move(entries));
  }

  bool take(const CollapseState::Candidate& c) {
    const double error = state_.error(c);
    if (error > settings_.max_error || c.cost > settings_.max_cost) {
      stats_->stuck = stats_->stopped_by_error = true;
      return false;
    }
    CollapseState::Candidate other;
    const bool pair = state_.mirrored(c, &other);
    // The faces the collapse removes: edges blamed on them are looked at again.
    state_.edge_faces(c.a, c.b, &removed_);
    if (pair) {
      state_.edge_faces(other.a, other.b, &faces_);
      removed_.insert(removed_.end(), faces_.begin(), faces_.end());
    }
    state_.collapse(c);
    if ((++stats_->collapses & 0xFFF) == 0 && progress_) progress_->set(2 * stats_->collapses);
    stats_->largest_cost = std::max(stats_->largest_cost, c.cost);
    stats_->largest_error = std::max(stats_->largest_error, error);
    if (stats_->cost_log) stats_->cost_log->push_back(c.cost);
    requeue_around(c.a);
    if (pair) requeue_around(other.a);  // the other side of the seam moved too
    for (const std::uint32_t f : removed_) requeue_blamed(f);
    // An anchored vertex does not move: the costs of all its edges changed, and their
    // entries are stale.
    for (std::uint32_t v : state_.newly_anchored()) {
      state_.neighbours(v, &ring_);
      for (std::uint32_t u : ring_)
        if (u != c.a) push(v, u);
    }
    return true;
  }

  // With no valid collapse left that meets the target, the cheapest valid one that
  // goes below it, then boundary edges split in two until it is met; without a
  // boundary edge (a closed surface, whose count is even) one triangle below. False
  // when there is none.
  bool take_deferred(std::vector<QueueEntry>& deferred) {
    std::sort(deferred.begin(), deferred.end(), [](const QueueEntry& x, const QueueEntry& y) { return later(y, x); });
    const bool any_boundary = state_.has_boundary_edge();
    const QueueEntry* first = nullptr;
    for (const QueueEntry& e : deferred) {
      if (!state_.alive(e.a) || !state_.alive(e.b)) continue;
      const CollapseState::Candidate c = state_.evaluate(e.a, e.b);
      if (!same_bits(c.cost, e.cost) || !state_.valid(c)) continue;
      if (!first) first = &e;
      if (!state_.split_can_make_up(c, settings_.target_triangles, any_boundary)) continue;
      return take_and_split(c);
    }
    return first && take_and_split(state_.evaluate(first->a, first->b));
  }

  bool take_and_split(const CollapseState::Candidate& c) {
    if (!take(c)) return true;
    stats_->parity = !state_.split_up_to(settings_.target_triangles);
    return true;
  }

  // A rejected edge is remembered with the face blamed, the one that would flip or
  // become a needle: it is looked at again when that face changes (a corner moves, or
  // it goes), not at every change near its ends. Around a hub (a cone's apex, a fan
  // of thousands) that keeps each collapse's work to the faces it changed; looking at
  // every edge rejected at the hub after each collapse beside it made the collapse
  // quadratic in the hub's valence. An edge blamed on no face (the link condition, a
  // doubled face) is remembered at both ends and looked at again when the faces
  // around either end change. An edge whose end moves or is anchored is costed anew
  // anyway (requeue_around, take).
  void reject(std::uint32_t a, std::uint32_t b, std::uint32_t blamed) {
    if (blamed == CollapseState::kNoFace) {
      unblamed_[a].push_back(b);
      unblamed_[b].push_back(a);
    } else {
      blamed_on_.value(blamed_on_.insert(blamed)).push_back(std::uint64_t(a) << 32 | b);
    }
  }

  // a's quadric changed: its edges get new costs. Its faces moved, so the edges blamed
  // on them may be valid now; so may the edges blamed on no face around it.
  void requeue_around(std::uint32_t a) {
    state_.neighbours(a, &ring_);
    for (std::uint32_t u : ring_) push(a, u);
    for (std::uint32_t u : ring_) requeue_unblamed(u, a);
    requeue_unblamed(a, a);
    state_.live_faces(a, &faces_);
    for (const std::uint32_t f : faces_) requeue_blamed(f);
  }

  // Each edge blamed on face f goes back into the queue, once (an edge rejected from
  // several entries must not come back as many), unless f still fails: then it is
  // still invalid, and stays until f changes again. Dead edges are dropped.
  void requeue_blamed(std::uint32_t f) {
    const std::int64_t at = blamed_on_.find(f);
    if (at < 0) return;
    std::vector<std::uint64_t>& list = blamed_on_.value(std::size_t(at));
    sort_small(&list);
    std::size_t kept = 0;
    for (std::size_t i = 0; i < list.size(); ++i) {
      if (i > 0 && list[i] == list[i - 1]) continue;
      const std::uint32_t a = std::uint32_t(list[i] >> 32), b = std::uint32_t(list[i]);
      if (!state_.alive(a) || !state_.alive(b)) continue;
      const CollapseState::Candidate c = state_.evaluate(a, b);
      if (!state_.keeps_face(c, f))
        list[kept++] = list[i];
      else
        heap_.push({c.cost, c.a, c.b});
    }
    list.resize(kept);
  }

  // Each edge blamed on no face at u goes back into the queue, once. Edges with a,
  // which requeue_around pushes anyway, and dead ones are dropped.
  void requeue_unblamed(std::uint32_t u, std::uint32_t a) {
    std::vector<std::uint32_t>& list = unblamed_[u];
    sort_small(&list);
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::uint32_t x = list[i];
      if ((i > 0 && x == list[i - 1]) || x == a || !state_.alive(x) || !state_.alive(u)) continue;
      const CollapseState::Candidate c = state_.evaluate(std::min(u, x), std::max(u, x));
      heap_.push({c.cost, c.a, c.b});
    }
    list.clear();
  }

  void push(std::uint32_t u, std::uint32_t v) {
    if (state_.locked(u) || state_.locked(v)) return;
    if (u > v) std::swap(u, v);
    const CollapseState::Candidate c = state_.evaluate(u, v);
    heap_.push({c.cost, u, v});
  }

  CollapseState& state_;
  const CollapseSettings& settings_;
  CollapseStats* stats_;
  ProgressPhase* progress_;
  QuadHeap heap_;
  // Per blamed face: its rejected edges, a << 32 | b.
  FlatHashMap<std::uint32_t, std::vector<std::uint64_t>> blamed_on_;
  std::vector<std::vector<std::uint32_t>> unblamed_;  // per vertex: the other ends of edges blamed on no face
  std::vector<std::uint32_t> ring_, faces_, removed_;
};

}  // namespace

void collapse_in_order(CollapseState& state, const CollapseSettings& settings, CollapseStats* stats,
                       ProgressPhase* progress) {
  LazyQueue(state, settings, stats, progress).run();
}

}  // namespace oocsimp
