#include "io/byte_sink.hpp"

#include <unistd.h>
#include <zlib.h>
#include <zstd.h>

#include <cerrno>
#include <cstring>

#include "io/error_text.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

bool has_zst_suffix(const std::string& path) {
  return path.size() >= 4 && path.compare(path.size() - 4, 4, ".zst") == 0;
}

bool has_gz_suffix(const std::string& path) { return path.size() >= 3 && path.compare(path.size() - 3, 3, ".gz") == 0; }

SinkCompression compression_for_path(const std::string& path) {
  if (has_zst_suffix(path)) return SinkCompression::zstd;
  if (has_gz_suffix(path)) return SinkCompression::gzip;
  return SinkCompression::none;
}

std::string without_compression_suffix(const std::string& path) {
  if (has_zst_suffix(path)) return path.substr(0, path.size() - 4);
  if (has_gz_suffix(path)) return path.substr(0, path.size() - 3);
  return path;
}

ByteSink::ByteSink(int fd, const std::string& path, SinkCompression compression, int level) : fd_(fd), path_(path) {
  buf_.resize(1 << 20);
  if (compression == SinkCompression::gzip) {
    gzip_ = new z_stream{};
    // windowBits 15 + 16: a gzip header and trailer around the deflate stream, as gzip(1) writes.
    if (deflateInit2(gzip_, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
      delete gzip_;
      throw IoError(path + ": cannot create a gzip compression stream");
    }
    zout_.resize(1 << 18);
  }
  if (compression == SinkCompression::zstd) {
    zstd_ = ZSTD_createCCtx();
    if (!zstd_) throw IoError(path + ": cannot create a zstd compression context");
    ZSTD_CCtx_setParameter(zstd_, ZSTD_c_compressionLevel, level);
    ZSTD_CCtx_setParameter(zstd_, ZSTD_c_checksumFlag, 1);
    zout_.resize(ZSTD_CStreamOutSize());
  }
}

ByteSink::~ByteSink() {
  if (zstd_) ZSTD_freeCCtx(zstd_);
  if (gzip_) {
    deflateEnd(gzip_);
    delete gzip_;
  }
}

void ByteSink::write_fd(const void* data, std::size_t n) {
  auto* p = static_cast<const unsigned char*>(data);
  while (n > 0) {
    ssize_t w = ::write(fd_, p, n);
    if (w < 0) {
      int err = errno;
      if (err == EINTR) continue;
      if (describe_error_) throw IoError(describe_error_(on_disk_, err));
      throw IoError(system_error_text(path_, "write failed", err));
    }
    p += w;
    n -= std::size_t(w);
    on_disk_ += std::uint64_t(w);
  }
}

void ByteSink::deflate_buffer(bool end) {
  gzip_->next_in = buf_.data();
  gzip_->avail_in = static_cast<uInt>(used_);  // the buffer is 1 MiB: it fits
  for (;;) {
    gzip_->next_out = zout_.data();
    gzip_->avail_out = static_cast<uInt>(zout_.size());
    const int r = deflate(gzip_, end ? Z_FINISH : Z_NO_FLUSH);
    if (r == Z_STREAM_ERROR) throw IoError(path_ + ": gzip compression failed");
    write_fd(zout_.data(), zout_.size() - gzip_->avail_out);
    if (end ? r == Z_STREAM_END : gzip_->avail_in == 0 && gzip_->avail_out != 0) break;
  }
}

void ByteSink::flush_buffer(bool end) {
  if (gzip_) {
    deflate_buffer(end);
  } else if (!zstd_) {
    write_fd(buf_.data(), used_);
  } else {
    ZSTD_inBuffer in{buf_.data(), used_, 0};
    for (;;) {
      ZSTD_outBuffer out{zout_.data(), zout_.size(), 0};
      std::size_t r = ZSTD_compressStream2(zstd_, &out, &in, end ? ZSTD_e_end : ZSTD_e_continue);
      if (ZSTD_isError(r)) throw IoError(path_ + ": zstd compression failed: " + ZSTD_getErrorName(r));
      write_fd(zout_.data(), out.pos);
      if (end ? r == 0 : in.pos == in.size) break;
    }
  }
  total_ += used_;
  used_ = 0;
}

void ByteSink::write_slow(const void* data, std::size_t n) {
  auto* p = static_cast<const unsigned char*>(data);
  while (n > 0) {
    if (used_ == buf_.size()) flush_buffer(false);
    std::size_t k = std::min(n, buf_.size() - used_);
    std::memcpy(buf_.data() + used_, p, k);
    used_ += k;
    p += k;
    n -= k;
  }
}

void ByteSink::finish() { flush_buffer(true); }

}  // namespace oocsimp
