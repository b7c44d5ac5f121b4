// Sequential, buffered writing to a file descriptor, compressing with zstd on demand.
#pragma once

#include <cstddef>
#include <cstring>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

typedef struct ZSTD_CCtx_s ZSTD_CCtx;

namespace oocsimp {

/// Writes through a 1 MiB buffer to `fd` (not owned). `path` only names the file in
/// errors. With `compress`, the content is written as one zstd frame.
class ByteSink {
 public:
  ByteSink(int fd, const std::string& path, bool compress, int level = 3);
  ~ByteSink();
  ByteSink(const ByteSink&) = delete;
  ByteSink& operator=(const ByteSink&) = delete;

  void write(const void* data, std::size_t n) {
    if (n <= buf_.size() - used_) {
      std::memcpy(buf_.data() + used_, data, n);
      used_ += n;
    } else {
      write_slow(data, n);
    }
  }
  void write(const std::string& s) { write(s.data(), s.size()); }
  /// Flushes everything (ends the zstd frame) and fsyncs nothing; throws IoError.
  void finish();
  /// Content bytes written so far (before compression).
  std::uint64_t bytes_written() const { return total_ + used_; }
  /// Replaces the message of a failed write: `describe(bytes already on disk, errno)`
  /// becomes the IoError's text, so the owner can say what the file was for and how
  /// much room it needs.
  void on_write_error(std::function<std::string(std::uint64_t, int)> describe) {
    describe_error_ = std::move(describe);
  }

 private:
  void write_slow(const void* data, std::size_t n);
  void flush_buffer(bool end);
  void write_fd(const void* data, std::size_t n);

  int fd_;
  std::string path_;
  std::vector<unsigned char> buf_;
  std::size_t used_ = 0;
  std::uint64_t total_ = 0;
  std::uint64_t on_disk_ = 0;
  ZSTD_CCtx* zstd_ = nullptr;
  std::vector<unsigned char> zout_;
  std::function<std::string(std::uint64_t, int)> describe_error_;
};

/// True when `path` ends with ".zst".
bool has_zst_suffix(const std::string& path);

}  // namespace oocsimp
