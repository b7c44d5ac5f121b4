// Sequential, buffered writing to a file descriptor, compressing with zstd or gzip on
// demand.
#pragma once

#include <cstddef>
#include <cstring>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

typedef struct ZSTD_CCtx_s ZSTD_CCtx;
struct z_stream_s;

namespace oocsimp {

/// How a ByteSink compresses what it writes.
enum class SinkCompression : std::uint8_t { none, zstd, gzip };

/// Writes through a 1 MiB buffer to `fd` (not owned). `path` only names the file in
/// errors. With zstd the content is written as one zstd frame, with gzip as one gzip
/// member (RFC 1952); `level` is zstd's (gzip takes zlib's default).
class ByteSink {
 public:
  ByteSink(int fd, const std::string& path, SinkCompression compression, int level = 3);
  /// With `compress`, zstd; uncompressed otherwise (temporary files).
  ByteSink(int fd, const std::string& path, bool compress, int level = 3)
      : ByteSink(fd, path, compress ? SinkCompression::zstd : SinkCompression::none, level) {}
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
  /// Flushes everything (ends the zstd frame or gzip member) and fsyncs nothing;
  /// throws IoError.
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
  void deflate_buffer(bool end);

  ZSTD_CCtx* zstd_ = nullptr;
  z_stream_s* gzip_ = nullptr;
  std::vector<unsigned char> zout_;
  std::function<std::string(std::uint64_t, int)> describe_error_;
};

/// True when `path` ends with ".zst".
bool has_zst_suffix(const std::string& path);
/// True when `path` ends with ".gz".
bool has_gz_suffix(const std::string& path);
/// The compression a file's name asks for: ".zst" zstd, ".gz" gzip, else none.
SinkCompression compression_for_path(const std::string& path);
/// `path` without its ".zst" or ".gz" suffix, if it has one.
std::string without_compression_suffix(const std::string& path);

}  // namespace oocsimp
