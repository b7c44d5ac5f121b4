#include "refine/collapse_passes.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "common/huge_pages.hpp"
#include "common/radix_sort.hpp"
#include "common/uninitialised_vector.hpp"
#include "refine/collapse_queue.hpp"
#include "runtime/progress_phase.hpp"

namespace oocsimp {

namespace {

// A pass takes no collapse dearer than this times the cost of the edge at which the
// passes would end were the cheapest edges all valid and apart (meshoptimizer's
// factor; see PassDriver).
constexpr double kPassCostSlack = 1.5;
// A pass that takes less than 1 / this of the collapses it wanted hands the rest to the
// lazy queue: each pass lists and sorts every edge again, the queue only those a
// collapse moved.
constexpr std::uint64_t kPassLeastShare = 16;
// A pass works out its collapses ahead (PassDriver::work_ahead) in batches of this
// many entries, when it looks at this many or more.
constexpr std::size_t kAheadBatch = 256;
constexpr std::size_t kAheadLeast = 1024;

// Garland & Heckbert's greedy order taken in passes, as meshoptimizer's simplifier
// does: each pass costs every edge (in parallel; an edge whose ends the last pass did
// not touch keeps its cost), sorts them, and takes the cheapest valid collapses in
// that order, each vertex in at most one collapse a pass, so that every cost taken is
// still the edge's cost then (a collapse changes the quadric and position of its two
// ends only, and the anchoring of neighbours it leaves non-manifold, which count as
// moved too). A pass stops when it has halved the count still to remove; the lazy
// queue then finishes in strict order. Where the lazy queue re-costs and re-checks
// the neighbourhood of every collapse, one at a time, a pass re-costs each edge at
// most once and checks only the collapses it looks at, several at once ahead of
// taking them (work_ahead).
//
// A pass also stops before a collapse dearer than kPassCostSlack times the cost of the
// edge at which the passes would end, were the cheapest edges all valid and apart
// (meshoptimizer's error limit per pass, meshopt_simplify). Edges it skips because an
// end was taken this pass may be far cheaper than the ones further down its list, and
// without the limit it went on to those: on a block of boxes tessellated into thin
// triangles, thousands of valid collapses of no error waited for the next pass while
// a pass took ones that cut boxes' corners, where the strict order cuts none (the
// distances are in docs/design.md, "The collapse in core", Passes). The limit leaves
// them to the next pass; a pass held back to a few collapses by it hands over to the
// lazy queue (kPassLeastShare).
class PassDriver {
 public:
  PassDriver(CollapseState& state, const CollapseSettings& settings, CollapseStats* stats, ProgressPhase* progress)
      : state_(state), settings_(settings), stats_(stats), progress_(progress), touched_(state.vertex_count(), 0) {}

  /// Passes until at most `stop_at` triangles are left, a pass takes nothing, or a
  /// collapse above settings.max_error comes up.
  void run(std::uint64_t stop_at) {
    while (state_.triangle_count() > stop_at && !at_max_error_) {
      const std::uint64_t excess = state_.triangle_count() - stop_at;
      const std::uint64_t pass_to = excess <= stop_at / 8 ? stop_at : stop_at + excess / 2;
      const std::uint64_t asked = wanted(pass_to);
      if (pass(pass_to, stop_at) * kPassLeastShare < asked) break;
    }
  }

 private:
  // Each edge (a, b), a < b, that may collapse, with its cost, into the first entries
  // of entries_; returns their count. An edge neither of whose ends the last pass
  // touched keeps its entry: its cost depends only on its ends (their quadrics,
  // positions and anchoring), unless a seam ties it to the ends' mirrors, and the
  // edges between untouched vertices are the same (a face that went had both ends of
  // its collapse). The edges of the touched vertices are listed again, each once,
  // block by block in parallel, then costed into their place in parallel.
  std::size_t cost_edges() {
    constexpr std::uint32_t kBlock = 4096;
    const std::uint32_t n = std::uint32_t(state_.vertex_count());
    const std::uint32_t last = stamp_;  // before the first pass every vertex holds it
    const bool seams = state_.has_seams();
    const auto touched = [&](std::uint32_t v) { return seams || touched_[v] == last; };
    std::size_t kept = 0;
    for (std::size_t i = 0; i < costed_; ++i) {
      const QueueEntry& e = entries_[i];
      if (!touched(e.a) && !touched(e.b)) entries_[kept++] = e;
    }
    // The first pass (and every pass, with seams) lists the edges of every vertex;
    // the others only those of the vertices the last pass touched.
    const bool every = seams || last == 0;
    const std::uint32_t listed_vertices = every ? n : std::uint32_t(touched_list_.size());
    const std::uint32_t blocks = (listed_vertices + kBlock - 1) / kBlock;
    std::vector<std::size_t> start(std::size_t(blocks) + 1, 0);
    std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> listed(blocks);
    tbb::parallel_for(std::uint32_t(0), blocks, [&](std::uint32_t block) {
      std::vector<std::uint32_t>& ring = rings_.local();
      std::vector<std::pair<std::uint32_t, std::uint32_t>>& edges = listed[block];
      for (std::uint32_t i = block * kBlock; i < std::min(listed_vertices, (block + 1) * kBlock); ++i) {
        const std::uint32_t v = every ? i : touched_list_[i];
        if (!state_.alive(v) || state_.locked(v) || !touched(v)) continue;
        state_.distinct_neighbours(v, &ring);
        for (std::uint32_t u : ring) {
          if (state_.locked(u)) continue;
          if (!touched(u)) {
            edges.emplace_back(std::min(u, v), std::max(u, v));
          } else if (u > v) {  // both touched: listed from the lower end
            edges.emplace_back(v, u);
          }
        }
      }
      start[block + 1] = edges.size();
    });
    touched_list_.clear();
    start[0] = kept;
    for (std::uint32_t block = 0; block < blocks; ++block) start[block + 1] += start[block];
    // entries_ only grows (the first pass has the most edges), and its new room is
    // not cleared: the costing below writes every entry.
    if (entries_.size() < start[blocks]) {
      UninitialisedVector<QueueEntry> grown;
      reserve_huge(&grown, start[blocks]);
      grown.assign(entries_.begin(), entries_.begin() + std::ptrdiff_t(kept));
      grown.resize(start[blocks]);
      entries_ = std::move(grown);
    }
    tbb::parallel_for(std::uint32_t(0), blocks, [&](std::uint32_t block) {
      QueueEntry* out = entries_.data() + start[block];
      // The far ends' quadrics are fetched a few edges ahead: each far end's is a
      // miss of the caches on a large mesh.
      const std::vector<std::pair<std::uint32_t, std::uint32_t>>& edges = listed[block];
      const Quadric* quadrics = state_.mesh().quadrics.data();
      constexpr std::size_t kAhead = 8;
      for (std::size_t i = 0; i < edges.size(); ++i) {
        if (i + kAhead < edges.size()) {
          const char* q = reinterpret_cast<const char*>(quadrics + edges[i + kAhead].second);
          __builtin_prefetch(q);
          __builtin_prefetch(q + sizeof(Quadric) - 1);
        }
        *out++ = {state_.evaluate(edges[i].first, edges[i].second).cost, edges[i].first, edges[i].second};
      }
      std::vector<std::pair<std::uint32_t, std::uint32_t>>().swap(listed[block]);
    });
    costed_ = start[blocks];
    return costed_;
  }

  // Marks v touched by this pass (its edges cost anew in the next), listing it once.
  void touch(std::uint32_t v, std::uint32_t stamp) {
    if (touched_[v] == stamp) return;
    touched_[v] = stamp;
    touched_list_.push_back(v);
  }

  // The collapses that would take the count to pass_to, each removing two faces.
  std::uint64_t wanted(std::uint64_t pass_to) const { return (state_.triangle_count() - pass_to + 1) / 2; }

  // One pass down to pass_to, the passes ending at stop_at; returns the collapses taken.
  std::uint64_t pass(std::uint64_t pass_to, std::uint64_t stop_at) {
    const std::size_t edges = cost_edges();
    // Entries past a few times the collapses wanted would not be reached: only the
    // cheapest are sorted (their set, and so the order, does not depend on the threads).
    const std::size_t look = std::size_t(std::min<std::uint64_t>(edges, look_factor_ * wanted(pass_to) + 16));
    auto earlier = [](const QueueEntry& x, const QueueEntry& y) { return later(y, x); };
    QueueEntry* const first = entries_.data();
    if (look < edges) std::nth_element(first, first + look, first + edges, earlier);
    msd_radix_sort(first, first + look, cost_key, vertices_key, earlier);
    // The cost limit: past the sorted entries the goal's cost is at least the last
    // one's, which then bounds none of them.
    const std::uint64_t goal = std::max<std::uint64_t>(1, (state_.triangle_count() - stop_at) / 2);
    const double limit = goal <= look ? kPassCostSlack * first[goal - 1].cost : HUGE_VAL;
    const std::uint32_t stamp = ++stamp_;
    std::uint64_t taken = 0;
    ahead_on_ = settings_.work_ahead && look >= kAheadLeast && !state_.has_seams() &&
                tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism) > 1 &&
                tbb::this_task_arena::max_concurrency() > 1;
    const std::size_t batch = ahead_on_ ? kAheadBatch : look;
    Step step = Step::next;
    for (std::size_t begin = 0; begin < look && step == Step::next; begin += batch) {
      const std::size_t end = std::min(look, begin + batch);
      if (ahead_on_) work_ahead(first + begin, first + end, stamp, limit);
      for (std::size_t i = begin; i < end && step == Step::next; ++i)
        step = take_entry(first[i], ahead_on_ ? &ahead_[i - begin] : nullptr, pass_to, limit, stamp, &taken);
    }
    const bool limited = step == Step::limited;
    stats_->collapses += taken;
    // Short of the pass's count, the cheapest edges were refused or shared a vertex:
    // the next pass looks further down the list; one that met it, or stopped at the
    // cost limit (further down is dearer still), less far.
    look_factor_ = state_.triangle_count() > pass_to && !limited ? std::min<std::uint64_t>(2 * look_factor_, 64)
                                                                 : std::max<std::uint64_t>(look_factor_ / 2, 2);
    if (progress_) progress_->set(2 * stats_->collapses);
    return taken;
  }

  enum class Step { next, stop, limited };

  // An entry's collapse as work_ahead() found it.
  struct Ahead {
    CollapseState::Candidate candidate;
    int faces_removed = 0;
    bool ready = false;  // worked out (else take_entry() works it out itself)
    bool valid = false;
  };

  // The walk of one entry of the sorted list: its collapse taken when both ends are
  // still untouched this pass, the collapse is valid, and it keeps to the target, the
  // cost limit and the error bounds. `known` (or null) is what work_ahead() found for
  // it; it is used when neither end is near a collapse taken since.
  Step take_entry(const QueueEntry& e, const Ahead* known, std::uint64_t pass_to, double limit, std::uint32_t stamp,
                  std::uint64_t* taken) {
    const std::uint64_t left = state_.triangle_count();
    if (left <= pass_to) return Step::stop;
    if (e.cost > limit) return Step::limited;
    if (touched_[e.a] == stamp || touched_[e.b] == stamp) return Step::next;
    if (known && !(known->ready && marks_[e.a] != moved_mark_ && marks_[e.b] != moved_mark_)) known = nullptr;
    if (known) ++stats_->worked_ahead;
    const CollapseState::Candidate c = known ? known->candidate : state_.evaluate(e.a, e.b);
    CollapseState::Candidate other;
    const bool pair = state_.mirrored(c, &other);
    if (pair && (touched_[other.a] == stamp || touched_[other.b] == stamp)) return Step::next;
    if (!(known ? known->valid : state_.valid(c))) return Step::next;
    // Never below an exact target (an edge may have many faces): the lazy queue
    // settles the last ones.
    const int removed = known ? known->faces_removed : state_.faces_removed(c);
    if (settings_.exact_count && left - settings_.target_triangles < std::uint64_t(removed)) return Step::next;
    // Skipped edges may be cheaper than this one now: whether the collapse stops at
    // max_error is for the lazy queue to say, in strict order of cost.
    const double error = state_.error(c);
    if (error > settings_.max_error || c.cost > settings_.max_cost) {
      at_max_error_ = true;
      return Step::stop;
    }
    // What the collapse changes, every vertex whose faces it touches, is marked: the
    // work done ahead for edges there is stale.
    if (ahead_on_)
      for (const std::uint32_t end : {c.a, c.b})
        state_.for_each_corner(end, [&](std::uint32_t u) { marks_[u] = moved_mark_; });
    state_.collapse(c);
    ++*taken;
    stats_->largest_cost = std::max(stats_->largest_cost, c.cost);
    stats_->largest_error = std::max(stats_->largest_error, error);
    if (stats_->cost_log) stats_->cost_log->push_back(c.cost);
    touch(e.a, stamp);
    touch(e.b, stamp);
    if (pair) touch(other.a, stamp), touch(other.b, stamp);
    for (std::uint32_t v : state_.newly_anchored()) touch(v, stamp);
    return Step::next;
  }

  // What take_entry() would work out for each entry of [begin, end), found on several
  // threads before any of them is taken: the candidate, whether it is valid and the
  // faces it removes. It depends only on the faces around the edge's ends, so it
  // holds at the entry's turn unless a collapse taken before then touched a face
  // there (take_entry() marks those vertices, and works such an entry out again).
  // Entries with an end already touched this pass, or shared with an earlier entry of
  // the batch (which is most likely taken, touching it), are left out.
  void work_ahead(const QueueEntry* begin, const QueueEntry* end, std::uint32_t stamp, double limit) {
    if (marks_.empty()) marks_.assign(state_.vertex_count(), 0);
    const std::size_t n = std::size_t(end - begin);
    ahead_.resize(n);
    ahead_todo_.clear();
    const std::uint32_t claimed = next_mark();
    for (std::size_t i = 0; i < n; ++i) {
      const QueueEntry& e = begin[i];
      ahead_[i].ready = false;
      if (e.cost > limit || touched_[e.a] == stamp || touched_[e.b] == stamp) continue;
      if (marks_[e.a] == claimed || marks_[e.b] == claimed) continue;
      marks_[e.a] = marks_[e.b] = claimed;
      ahead_todo_.push_back(std::uint32_t(i));
    }
    moved_mark_ = next_mark();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ahead_todo_.size(), 8),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t j = r.begin(); j != r.end(); ++j) {
                          const std::uint32_t i = ahead_todo_[j];
                          Ahead& k = ahead_[i];
                          k.candidate = state_.evaluate(begin[i].a, begin[i].b);
                          k.valid = state_.valid(k.candidate);
                          k.faces_removed = k.valid ? state_.faces_removed(k.candidate) : 0;
                          k.ready = true;
                        }
                      });
  }

  // A new value for marks_, none of whose entries holds it yet.
  std::uint32_t next_mark() {
    if (++mark_ == 0) {
      std::fill(marks_.begin(), marks_.end(), 0);
      mark_ = 1;
    }
    return mark_;
  }

  CollapseState& state_;
  const CollapseSettings& settings_;
  CollapseStats* stats_;
  ProgressPhase* progress_;
  std::vector<std::uint32_t> touched_;       // the pass that last moved or removed each vertex
  std::vector<std::uint32_t> touched_list_;  // the vertices the last pass touched, each once
  UninitialisedVector<QueueEntry> entries_;  // the costed entries, each written before it is read
  std::size_t costed_ = 0;                   // the entries the last pass costed (in any order after it)
  tbb::enumerable_thread_specific<std::vector<std::uint32_t>> rings_;  // a thread's neighbour list
  std::uint32_t stamp_ = 0;
  // Per vertex: claimed by an entry worked out ahead in this batch, or (moved_mark_)
  // near a collapse taken since the batch was worked out.
  std::vector<std::uint32_t> marks_;  // allocated by the first work_ahead()
  std::uint32_t mark_ = 0, moved_mark_ = 0;
  bool ahead_on_ = false;     // this pass works its collapses out ahead
  std::vector<Ahead> ahead_;  // the batch's entries, worked out ahead
  std::vector<std::uint32_t> ahead_todo_;
  std::uint64_t look_factor_ = 2;  // entries sorted per collapse wanted
  bool at_max_error_ = false;
};

}  // namespace

void collapse_in_passes(CollapseState& state, const CollapseSettings& settings, std::uint64_t stop_at,
                        CollapseStats* stats, ProgressPhase* progress) {
  PassDriver(state, settings, stats, progress).run(stop_at);
}

}  // namespace oocsimp
