// Sequential, buffered reading of an input opened once, decompressing zstd on the fly.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "common/uninitialised_vector.hpp"

typedef struct ZSTD_DCtx_s ZSTD_DCtx;

struct z_stream_s;  // zlib's z_stream

namespace oocsimp {

class TempFile;

/// An input file opened once. Every pass over it (header, vertices, each triangle pass,
/// the mapping of the positions) reads this one descriptor with pread, so a file that
/// is replaced or renamed between passes cannot mix two files. An input that cannot be
/// read twice (a FIFO, a pipe, a terminal, "-" for standard input) is copied into a
/// temporary file as far as it has been read, and every pass reads the copy: the first
/// pass never waits for data no pass asked for, and a stream without end (/dev/zero)
/// costs only what the readers consumed before rejecting it.
class InputFile {
 public:
  /// Opens `path` ("-" is standard input, named "stdin" in messages); a copy of a
  /// stream goes to `temp_dir`. Throws IoError.
  static std::shared_ptr<InputFile> open(const std::string& path, const std::string& temp_dir);
  ~InputFile();
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  /// The name for messages.
  const std::string& name() const { return name_; }
  /// True for a stream read through a temporary copy.
  bool streamed() const { return copy_ != nullptr; }
  /// True when size() is the whole input: a regular file, or a stream read to its end.
  bool size_known() const { return !copy_ || stream_ended_; }
  /// Size in bytes; for a stream, the bytes copied so far.
  std::uint64_t size() const { return size_; }
  /// Reads up to n bytes at `offset`; fewer only at the end of the input. Throws IoError.
  std::size_t read_at(std::uint64_t offset, void* dst, std::size_t n);
  /// Copies the rest of a stream, so that size() is known; nothing for a regular file.
  void read_to_end();
  /// The descriptor that read_at() reads (the copy for a stream), for mapping.
  int fd() const;

 private:
  InputFile() = default;
  void copy_up_to(std::uint64_t end);

  std::string name_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
  std::unique_ptr<TempFile> copy_;
  bool stream_ended_ = false;
};

/// Reads an InputFile front to back through a buffer. Content that starts with a zstd
/// frame (or a skippable frame, as pzstd writes) is decompressed as a stream of frames,
/// as `zstd -d` does; content that starts with a gzip member (RFC 1952) as a stream of
/// members, as `gzip -d` does. Offsets are positions in the (decompressed) content; lines are
/// counted from 1 by next_line().
class ByteSource {
 public:
  explicit ByteSource(std::shared_ptr<InputFile> file);
  ~ByteSource();
  ByteSource(const ByteSource&) = delete;
  ByteSource& operator=(const ByteSource&) = delete;

  /// The name of the input, for messages.
  const std::string& path() const { return file_->name(); }
  const std::shared_ptr<InputFile>& input() const { return file_; }
  bool compressed() const { return zstd_ != nullptr || gzip_ != nullptr; }
  /// "zstd", "gzip", or "" for content read as it is.
  const char* compression() const { return zstd_ ? "zstd" : gzip_ ? "gzip" : ""; }
  /// True when file_size() is the size of the content: an uncompressed regular file.
  /// Checks of counts against the size, and reading positions in place, need it.
  bool content_size_known() const { return !compressed() && !file_->streamed(); }
  /// Size of the file on disk (compressed size for zstd); 0 while unknown (a stream
  /// not read to its end), which progress reports show as such.
  std::uint64_t file_size() const { return file_->size_known() ? file_->size() : 0; }
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
  /// Returns the next line without its line end; false at the end. A line ends at
  /// "\n", "\r\n" or a lone "\r"; a last line without one is returned too. A UTF-8 byte
  /// order mark at the start of the content is dropped from the first line. A line
  /// longer than `max_length` bytes throws InputError "FILE: line N: ..." (with the
  /// message `too_long` when given) as soon as that many bytes are read without a line
  /// end, so binary data or a stream without newlines cannot grow the buffer.
  bool next_line(std::string_view* line, std::size_t max_length = kMaxLine, const char* too_long = nullptr);
  /// True when all content has been consumed.
  bool at_end();
  /// Skips n bytes; throws InputError at a premature end.
  void skip(std::uint64_t n, const char* what);

  static constexpr std::size_t kMaxPeek = 1 << 16;
  /// Longest data line of a text format (a vertex, a face, an STL keyword line).
  static constexpr std::size_t kMaxLine = 64 << 10;
  /// Longest header line, and longest whole PLY header.
  static constexpr std::size_t kMaxHeaderLine = 1 << 20;

 private:
  bool refill_for(std::size_t n);
  std::size_t fill_raw(unsigned char* dst, std::size_t cap);
  std::size_t fill_gzip(unsigned char* dst, std::size_t cap);
  bool refill_compressed(const char* format);
  std::size_t read_raw(void* dst, std::size_t cap);
  [[noreturn]] void line_too_long(std::size_t max_length, const char* too_long) const;

  std::shared_ptr<InputFile> file_;
  std::uint64_t raw_consumed_ = 0;
  std::uint64_t base_ = 0;  // content offset of buf_[0]
  std::size_t pos_ = 0, end_ = 0;
  std::uint64_t line_ = 0;
  bool eof_ = false;
  UninitialisedVector<unsigned char> buf_;  // bytes past end_ are never read
  ZSTD_DCtx* zstd_ = nullptr;
  z_stream_s* gzip_ = nullptr;
  std::vector<unsigned char> zin_;
  std::size_t zin_pos_ = 0, zin_end_ = 0;
  bool raw_eof_ = false;
  bool frame_done_ = true;
};

/// True when `head` (at least 4 bytes) starts a zstd frame or a skippable frame.
bool starts_zstd_frame(const unsigned char* head);

}  // namespace oocsimp
