// The entries the collapse drivers order edges by (lazy_queue.cpp, collapse_passes.cpp):
// an edge and its cost, the cheapest first, ties by the vertices, so that the order is
// a strict total one and the same for any thread count.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <utility>
#include <vector>

namespace oocsimp {

struct QueueEntry {
  double cost;
  std::uint32_t a, b;
};

// std::push_heap keeps the largest on top: "larger" is the later collapse, so the
// cheapest comes first, ties by the vertices (the same order for any thread count).
// A function object, so that the heap's sifting inlines it.
struct Later {
  bool operator()(const QueueEntry& x, const QueueEntry& y) const {
    if (x.cost != y.cost) return x.cost > y.cost;
    if (x.a != y.a) return x.a > y.a;
    return x.b > y.b;
  }
};
constexpr Later later{};

inline bool same_bits(double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; }

// A key for msd_radix_sort (common/radix_sort.hpp) in Later's order, cheapest first:
// the cost's bits. A cost is never below 0 (an infinity at most, for a NaN), and the
// bits of doubles of one sign order as the numbers do; -0, equal to 0, keys as 0.
inline std::uint64_t cost_key(const QueueEntry& e) {
  std::uint64_t bits;
  std::memcpy(&bits, &e.cost, sizeof bits);
  return bits & ~(std::uint64_t(1) << 63);
}
// Later's order among equal costs: by the vertices.
inline std::uint64_t vertices_key(const QueueEntry& e) { return std::uint64_t(e.a) << 32 | e.b; }

// A min-heap with four children per node: the queue holds millions of entries, most
// of them stale, and a pop walks its depth; four 16-byte children share a cache line,
// so a level costs one miss where a binary heap's two levels cost two. The order is
// Later's, a strict total order, so the pops are those of any other heap.
class QuadHeap {
 public:
  bool empty() const { return items_.empty(); }
  void reserve(std::size_t n) { items_.reserve(n); }
  /// Takes `items` and orders them.
  void assign(std::vector<QueueEntry> items) {
    items_ = std::move(items);
    for (std::size_t i = items_.size(); i-- > 0;) sift_down(i);
  }
  void push(const QueueEntry& e) {
    std::size_t i = items_.size();
    items_.push_back(e);
    while (i > 0) {
      const std::size_t parent = (i - 1) / 4;
      if (!later(items_[parent], e)) break;
      items_[i] = items_[parent];
      i = parent;
    }
    items_[i] = e;
  }
  QueueEntry pop() {
    const QueueEntry top = items_.front();
    items_.front() = items_.back();
    items_.pop_back();
    if (!items_.empty()) sift_down(0);
    return top;
  }

 private:
  void sift_down(std::size_t i) {
    const QueueEntry e = items_[i];
    const std::size_t n = items_.size();
    for (;;) {
      const std::size_t first = 4 * i + 1;
      if (first >= n) break;
      std::size_t best = first;
      const std::size_t last = std::min(first + 4, n);
      for (std::size_t c = first + 1; c < last; ++c)
        if (later(items_[best], items_[c])) best = c;
      if (!later(e, items_[best])) break;
      items_[i] = items_[best];
      i = best;
    }
    items_[i] = e;
  }

  std::vector<QueueEntry> items_;
};

}  // namespace oocsimp
