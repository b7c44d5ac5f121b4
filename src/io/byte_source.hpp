// Sequential, buffered reading of a file, decompressing zstd on the fly.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

typedef struct ZSTD_DCtx_s ZSTD_DCtx;

namespace oocsimp {

/// Reads a file front to back through a buffer. Files that start with the zstd magic
/// number are decompressed as a stream. Offsets are positions in the (decompressed)
/// content; lines are counted from 1 by next_line().
class ByteSource {
 public:
  /// Opens `path`; throws IoError when it cannot be opened.
  explicit ByteSource(const std::string& path);
  ~ByteSource();
  ByteSource(const ByteSource&) = delete;
  ByteSource& operator=(const ByteSource&) = delete;

  const std::string& path() const { return path_; }
  bool compressed() const { return zstd_ != nullptr; }
  /// Size of the file on disk (compressed size for zstd).
  std::uint64_t file_size() const { return file_size_; }
  /// Bytes of the file on disk consumed so far, for progress.
  std::uint64_t raw_consumed() const { return raw_consumed_; }
  /// Offset in the content of the next unread byte.
  std::uint64_t offset() const { return base_ + pos_; }
  /// Number of the line next_line() returned last (1-based).
  std::uint64_t line_number() const { return line_; }

  /// Makes `n` bytes available at the returned pointer without consuming them;
  /// returns nullptr when the content ends first. n must be at most kMaxPeek.
  const unsigned char* peek(std::size_t n) {
    if (end_ - pos_ >= n) return buf_.data() + pos_;
    return refill_for(n) ? buf_.data() + pos_ : nullptr;
  }
  void consume(std::size_t n) { pos_ += n; }
  /// Reads exactly n bytes or throws InputError "unexpected end of file" naming the
  /// offset and `what` was being read.
  void read_exact(void* dst, std::size_t n, const char* what);
  /// Returns the next line without its '\n' (and '\r'); false at the end. A last line
  /// without '\n' is returned too. Lines may be of any length.
  bool next_line(std::string_view* line);
  /// True when all content has been consumed.
  bool at_end();
  /// Skips n bytes (seeks when uncompressed); throws InputError at a premature end.
  void skip(std::uint64_t n, const char* what);

  static constexpr std::size_t kMaxPeek = 1 << 16;

 private:
  bool refill_for(std::size_t n);
  std::size_t fill_raw(unsigned char* dst, std::size_t cap);

  std::string path_;
  int fd_ = -1;
  std::uint64_t file_size_ = 0;
  std::uint64_t raw_consumed_ = 0;
  std::uint64_t base_ = 0;  // content offset of buf_[0]
  std::size_t pos_ = 0, end_ = 0;
  std::uint64_t line_ = 0;
  bool eof_ = false;
  std::vector<unsigned char> buf_;
  ZSTD_DCtx* zstd_ = nullptr;
  std::vector<unsigned char> zin_;
  std::size_t zin_pos_ = 0, zin_end_ = 0;
  bool raw_eof_ = false;
  bool frame_done_ = true;
};

/// True when the file at `path` starts with the zstd frame magic number.
bool is_zstd_file(const std::string& path);

}  // namespace oocsimp
