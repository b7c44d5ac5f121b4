// An append-only array stored in fixed-size pages.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

namespace oocsimp {

/// Like std::vector for push_back and indexing, but grows one page at a time: no
/// reallocation copies and at most one partly used page, so a table of millions of
/// records never holds twice its size while it grows. Elements do not move.
template <class T, std::size_t kPageBits = 12>
class PagedArray {
 public:
  static constexpr std::size_t kPage = std::size_t(1) << kPageBits;

  T& operator[](std::size_t i) { return pages_[i >> kPageBits][i & (kPage - 1)]; }
  const T& operator[](std::size_t i) const { return pages_[i >> kPageBits][i & (kPage - 1)]; }
  std::size_t size() const { return size_; }
  /// Appends a value-initialised element and returns it.
  T& emplace_back() {
    if ((size_ >> kPageBits) == pages_.size()) pages_.push_back(std::make_unique<T[]>(kPage));
    T& e = (*this)[size_++];
    e = T{};
    return e;
  }
  void push_back(const T& v) { emplace_back() = v; }
  /// Empties the array, keeping its pages for reuse.
  void clear() { size_ = 0; }
  std::size_t capacity() const { return pages_.size() * kPage; }

 private:
  std::vector<std::unique_ptr<T[]>> pages_;
  std::size_t size_ = 0;
};

}  // namespace oocsimp
