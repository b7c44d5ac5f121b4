// A bounding-volume hierarchy over points or triangles held in memory (metrics/).
#pragma once

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "common/triangle_geometry.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {
namespace metrics {

/// A binary hierarchy of axis-aligned boxes over `count` primitives, built by median
/// splits along the longest axis of the primitives' centres. It is stored as an
/// implicit heap (node i has children 2i+1 and 2i+2): every subtree has fixed slots,
/// so the top levels are built in parallel and the result is the same for any thread
/// count. Leaves hold at most `leaf_size` primitives; order() lists the primitives in
/// leaf order, and callers permute their own arrays by it so that a leaf's
/// primitives are the contiguous range [begin, end) (see permuted()).
class BoxTree {
 public:
  struct Node {
    Box3d box;  ///< encloses the primitives order()[begin, end)
    std::uint32_t begin = 0, end = 0;
  };

  /// Builds over primitives 0..count-1; `box_of(i)` returns the box of primitive i
  /// (a degenerate box for a point). Throws UsageError beyond 2^32 - 1 primitives.
  template <class BoxOf>
  BoxTree(std::uint64_t count, std::uint32_t leaf_size, const BoxOf& box_of);

  bool empty() const { return nodes_[0].end == 0; }
  const std::vector<std::uint32_t>& order() const { return order_; }
  /// Frees the permutation once the callers have applied it.
  void release_order() { std::vector<std::uint32_t>().swap(order_); }
  std::size_t node_count() const { return nodes_.size(); }
  const Node& node(std::size_t i) const { return nodes_[i]; }
  bool is_leaf(std::size_t i) const { return nodes_[i].end - nodes_[i].begin <= leaf_size_; }

  /// For every node, the largest `value(k)` over the primitives in its range (leaf
  /// order), 0 for an empty one: per-node bounds that prune traversals.
  template <class Value>
  std::vector<double> max_per_node(const Value& value) const;

  /// The smallest `primitive_distance2(k)` (k in leaf order) below `bound2`, or
  /// `bound2` when none is. Visits the nearer child first and skips every node whose
  /// box is at least the best so far from p, so primitive_distance2(k) must never be
  /// less than point_box_distance2(p, box of k).
  template <class PrimitiveDistance2>
  double nearest(const Vec3d& p, double bound2, const PrimitiveDistance2& primitive_distance2) const;

  /// Calls `visit_leaf(node index)` for every leaf reached by descending from the root
  /// into the nodes for which `enter(node index)` is true, until visit_leaf returns
  /// false; returns false when it did.
  template <class Enter, class VisitLeaf>
  bool for_each_leaf_reached(const Enter& enter, const VisitLeaf& visit_leaf) const;

 private:
  // A tree over < 2^32 primitives with at least one per leaf has fewer than 33
  // levels; a depth-first traversal holds at most one pending sibling per level.
  static constexpr int kStackSize = 64;

  // A primitive's centre, in float: it only steers the splits (the boxes are exact),
  // and halves the build's memory.
  struct BuildItem {
    float centre[3];
    std::uint32_t index;
  };
  template <class BoxOf>
  void build(std::size_t node, std::uint32_t begin, std::uint32_t end, std::vector<BuildItem>& items,
             const BoxOf& box_of);

  std::uint32_t leaf_size_;
  std::vector<Node> nodes_;
  std::vector<std::uint32_t> order_;
};

/// `values` reordered so that element k is values[order[k]].
template <class T>
std::vector<T> permuted(const std::vector<T>& values, const std::vector<std::uint32_t>& order) {
  std::vector<T> out;
  out.reserve(order.size());
  for (std::uint32_t i : order) out.push_back(values[i]);
  return out;
}

template <class BoxOf>
BoxTree::BoxTree(std::uint64_t count, std::uint32_t leaf_size, const BoxOf& box_of)
    : leaf_size_(std::max<std::uint32_t>(1, leaf_size)) {
  if (count > std::numeric_limits<std::uint32_t>::max())
    throw UsageError("too many samples or triangles for one search tree (at most 2^32 - 1)");
  std::uint32_t n = std::uint32_t(count);
  // Median splits halve the ranges (rounding up at worst), so ceil(n / 2^depth)
  // bounds every range at that depth; the tree ends where it fits in a leaf.
  int depth = 0;
  while ((std::uint64_t(n) + (std::uint64_t(1) << depth) - 1) >> depth > leaf_size_) ++depth;
  nodes_.resize((std::size_t(2) << depth) - 1);
  std::vector<BuildItem> items(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    Box3d b = box_of(i);
    items[i] = {{float(0.5 * (b.min.x + b.max.x)), float(0.5 * (b.min.y + b.max.y)), float(0.5 * (b.min.z + b.max.z))},
                i};
  }
  build(0, 0, n, items, box_of);
  order_.resize(n);
  for (std::uint32_t k = 0; k < n; ++k) order_[k] = items[k].index;
}

template <class BoxOf>
void BoxTree::build(std::size_t node, std::uint32_t begin, std::uint32_t end, std::vector<BuildItem>& items,
                    const BoxOf& box_of) {
  Node& out = nodes_[node];
  out.begin = begin;
  out.end = end;
  if (end - begin <= leaf_size_) {
    for (std::uint32_t k = begin; k < end; ++k) {
      Box3d b = box_of(items[k].index);
      expand(out.box, b.min);
      expand(out.box, b.max);
    }
    return;
  }
  float lo[3] = {items[begin].centre[0], items[begin].centre[1], items[begin].centre[2]};
  float hi[3] = {lo[0], lo[1], lo[2]};
  for (std::uint32_t k = begin + 1; k < end; ++k)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], items[k].centre[a]);
      hi[a] = std::max(hi[a], items[k].centre[a]);
    }
  float extent[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
  int axis = int(std::max_element(extent, extent + 3) - extent);
  std::uint32_t mid = begin + (end - begin) / 2;
  // Ties are broken by index, so the split does not depend on the input permutation.
  std::nth_element(items.begin() + begin, items.begin() + mid, items.begin() + end,
                   [axis](const BuildItem& a, const BuildItem& b) {
                     return a.centre[axis] < b.centre[axis] || (a.centre[axis] == b.centre[axis] && a.index < b.index);
                   });
  std::size_t left = 2 * node + 1;
  constexpr std::uint32_t kParallelRange = 1 << 14;  // below this a task costs more than it saves
  if (end - begin >= kParallelRange) {
    tbb::parallel_invoke([&] { build(left, begin, mid, items, box_of); },
                         [&] { build(left + 1, mid, end, items, box_of); });
  } else {
    build(left, begin, mid, items, box_of);
    build(left + 1, mid, end, items, box_of);
  }
  out.box = nodes_[left].box;
  expand(out.box, nodes_[left + 1].box.min);
  expand(out.box, nodes_[left + 1].box.max);
}

template <class Value>
std::vector<double> BoxTree::max_per_node(const Value& value) const {
  std::vector<double> result(nodes_.size(), 0.0);
  // Children have larger indices than their parent: one backward sweep suffices.
  // Unused heap slots are empty leaves and keep 0.
  for (std::size_t i = nodes_.size(); i-- > 0;) {
    if (is_leaf(i)) {
      for (std::uint32_t k = nodes_[i].begin; k < nodes_[i].end; ++k) result[i] = std::max(result[i], value(k));
    } else {
      result[i] = std::max(result[2 * i + 1], result[2 * i + 2]);
    }
  }
  return result;
}

template <class PrimitiveDistance2>
double BoxTree::nearest(const Vec3d& p, double bound2, const PrimitiveDistance2& primitive_distance2) const {
  if (empty()) return bound2;
  struct Pending {
    std::size_t node;
    double distance2;
  };
  Pending stack[kStackSize];
  int top = 0;
  double best2 = bound2;
  stack[top++] = {0, point_box_distance2(p, nodes_[0].box)};
  while (top > 0) {
    Pending e = stack[--top];
    if (e.distance2 >= best2) continue;
    const Node& n = nodes_[e.node];
    if (is_leaf(e.node)) {
      for (std::uint32_t k = n.begin; k < n.end; ++k) best2 = std::min(best2, primitive_distance2(k));
      continue;
    }
    std::size_t left = 2 * e.node + 1;
    double dl = point_box_distance2(p, nodes_[left].box), dr = point_box_distance2(p, nodes_[left + 1].box);
    if (dl <= dr) {
      stack[top++] = {left + 1, dr};
      stack[top++] = {left, dl};
    } else {
      stack[top++] = {left, dl};
      stack[top++] = {left + 1, dr};
    }
  }
  return best2;
}

template <class Enter, class VisitLeaf>
bool BoxTree::for_each_leaf_reached(const Enter& enter, const VisitLeaf& visit_leaf) const {
  std::size_t stack[kStackSize];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    std::size_t i = stack[--top];
    if (!enter(i)) continue;
    if (is_leaf(i)) {
      if (!visit_leaf(i)) return false;
    } else {
      stack[top++] = 2 * i + 2;
      stack[top++] = 2 * i + 1;
    }
  }
  return true;
}

}  // namespace metrics
}  // namespace oocsimp
