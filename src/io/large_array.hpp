// Arrays as large as the output or the input: in the heap while they are small next
// to the memory budget, else in a mapped temporary file, whose pages the kernel
// writes out and reads back as they are used and which never count as heap.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "common/huge_pages.hpp"
#include "io/mapped_file.hpp"
#include "oocsimp/names.hpp"  // default_temp_dir

namespace oocsimp {

/// Where a run's large arrays go: the heap up to `heap_limit` bytes an array, a mapped
/// temporary file in `temp_dir` beyond.
struct ArrayPlace {
  std::string temp_dir;
  std::uint64_t heap_limit = std::numeric_limits<std::uint64_t>::max();

  /// The place of a run with a memory budget of `budget` bytes (0: unbounded) and its
  /// temporary folder (empty: default_temp_dir()): an array may take an eighth of the
  /// budget in the heap.
  static ArrayPlace within(std::uint64_t budget, const std::string& temp_dir) {
    ArrayPlace p;
    p.temp_dir = temp_dir.empty() ? default_temp_dir() : temp_dir;
    if (budget) p.heap_limit = budget / 8;
    return p;
  }
  /// The heap bytes an array of `bytes` takes here: all or none.
  std::uint64_t heap_bytes(std::uint64_t bytes) const { return bytes <= heap_limit ? bytes : 0; }
};

/// A resizable array of trivially copyable values, zeroed when it grows, placed as an
/// ArrayPlace says when it is first sized. Same values whichever place it has.
template <class T>
class LargeArray {
  static_assert(std::is_trivially_copyable<T>::value, "LargeArray holds plain values");

 public:
  LargeArray() = default;
  /// An array in the heap: the values of `values`.
  explicit LargeArray(std::vector<T> values) : heap_(std::move(values)), size_(heap_.size()) {}

  /// `count` zeros, in the heap when they fit place.heap_limit, else in a file named
  /// after `name`. Throws IoError when the file cannot be made.
  void assign_zeroed(std::size_t count, const ArrayPlace& place, const char* name) {
    clear();
    if (std::uint64_t(count) * sizeof(T) <= place.heap_limit) {
      reserve_filled(&heap_, count);
      heap_.assign(count, T());
    } else {
      file_ = std::make_unique<MappedScratch>(place.temp_dir, std::string("oocsimp-") + name,
                                              std::uint64_t(count) * sizeof(T));
    }
    size_ = count;
  }
  /// Grows (with zeros) or shrinks to `count` values where it already is.
  void resize(std::size_t count) {
    if (file_) {
      file_->resize(std::uint64_t(count) * sizeof(T));
    } else {
      heap_.resize(count);
    }
    size_ = count;
  }

  T* data() { return file_ ? reinterpret_cast<T*>(file_->data()) : heap_.data(); }
  const T* data() const { return file_ ? reinterpret_cast<const T*>(file_->data()) : heap_.data(); }
  T& operator[](std::size_t i) { return data()[i]; }
  const T& operator[](std::size_t i) const { return data()[i]; }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  /// Whether the values are in a file.
  bool mapped() const { return file_ != nullptr; }

  /// The values in a heap vector: moved out when they are in the heap, else copied.
  /// The array is left empty.
  std::vector<T> take() {
    std::vector<T> out;
    if (file_) {
      out.resize(size_);
      if (size_) std::memcpy(out.data(), file_->data(), size_ * sizeof(T));
    } else {
      out = std::move(heap_);
    }
    clear();
    return out;
  }
  void clear() {
    std::vector<T>().swap(heap_);
    file_.reset();
    size_ = 0;
  }

 private:
  std::vector<T> heap_;
  std::unique_ptr<MappedScratch> file_;
  std::size_t size_ = 0;
};

/// A LargeArray filled by appending, of unknown final size: its room doubles when it
/// is full, and it moves from the heap into a file when the room outgrows the place's
/// heap limit, so reading a file of any size into it never holds more than that.
template <class T>
class AppendArray {
 public:
  AppendArray(ArrayPlace place, const char* name) : place_(std::move(place)), name_(name) {}
  void push_back(const T& value) {
    if (size_ == values_.size()) grow();
    values_[size_++] = value;
  }
  const T& operator[](std::size_t i) const { return values_[i]; }
  T& operator[](std::size_t i) { return values_[i]; }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }

 private:
  void grow() {
    const std::size_t room = values_.size() < 1024 ? 1024 : 2 * values_.size();
    if (values_.mapped() || std::uint64_t(room) * sizeof(T) <= place_.heap_limit) {
      values_.resize(room);
      return;
    }
    LargeArray<T> moved;
    moved.assign_zeroed(room, place_, name_);
    if (size_) std::memcpy(moved.data(), values_.data(), size_ * sizeof(T));
    values_ = std::move(moved);
  }

  ArrayPlace place_;
  const char* name_;
  LargeArray<T> values_;
  std::size_t size_ = 0;
};

}  // namespace oocsimp
