// An append-only array stored in fixed-size pages.
#pragma once

#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <vector>

#include "common/huge_pages.hpp"

namespace oocsimp {

/// Like std::vector for push_back and indexing, but grows one page at a time: no
/// reallocation copies and at most one partly used page, so a table of millions of
/// records never holds twice its size while it grows. Elements do not move.
/// A page is raw storage: each element is value-initialised when it is appended, where
/// it is about to be written, not a whole page at a time beforehand. From the second
/// page on (a table that grows past one will fill its pages), a page is faulted in by
/// one call when it is added (populate_pages): the tables of millions of cells grew
/// their pages on the serial stage of a pipeline, a page fault per 4 KiB.
template <class T, std::size_t kPageBits = 12>
class PagedArray {
 public:
  static constexpr std::size_t kPage = std::size_t(1) << kPageBits;

  PagedArray() = default;
  PagedArray(PagedArray&& other) noexcept : pages_(std::move(other.pages_)), size_(other.size_) { other.size_ = 0; }
  PagedArray& operator=(PagedArray&& other) noexcept {
    if (this != &other) {
      destroy_elements();
      pages_ = std::move(other.pages_);
      size_ = other.size_;
      other.size_ = 0;
    }
    return *this;
  }
  ~PagedArray() { destroy_elements(); }

  T& operator[](std::size_t i) { return pages_[i >> kPageBits].get()[i & (kPage - 1)]; }
  const T& operator[](std::size_t i) const { return pages_[i >> kPageBits].get()[i & (kPage - 1)]; }
  std::size_t size() const { return size_; }
  /// Appends a value-initialised element and returns it.
  T& emplace_back() {
    if ((size_ >> kPageBits) == pages_.size()) {
      std::unique_ptr<T, FreePage> page(
          static_cast<T*>(::operator new(kPage * sizeof(T), std::align_val_t(alignof(T)))));
      if (!pages_.empty()) populate_pages(page.get(), kPage * sizeof(T));
      pages_.push_back(std::move(page));  // owned first: a failed push_back frees it
    }
    T* slot = pages_[size_ >> kPageBits].get() + (size_ & (kPage - 1));
    ++size_;
    return *::new (static_cast<void*>(slot)) T();
  }
  void push_back(const T& v) { emplace_back() = v; }
  /// Empties the array, keeping its pages for reuse.
  void clear() {
    destroy_elements();
    size_ = 0;
  }
  std::size_t capacity() const { return pages_.size() * kPage; }

 private:
  void destroy_elements() {
    if constexpr (!std::is_trivially_destructible<T>::value)
      for (std::size_t i = 0; i < size_; ++i) (*this)[i].~T();
  }
  struct FreePage {
    void operator()(T* page) const { ::operator delete(page, std::align_val_t(alignof(T))); }
  };
  std::vector<std::unique_ptr<T, FreePage>> pages_;
  std::size_t size_ = 0;
};

}  // namespace oocsimp
