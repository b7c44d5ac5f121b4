#include "io/byte_source.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zstd.h>

#include <cerrno>
#include <cstring>

#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {
constexpr std::size_t kBufferSize = 1 << 20;
constexpr unsigned char kZstdMagic[4] = {0x28, 0xB5, 0x2F, 0xFD};
}  // namespace

bool is_zstd_file(const std::string& path) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  unsigned char m[4] = {0, 0, 0, 0};
  ssize_t n = ::pread(fd, m, 4, 0);
  ::close(fd);
  return n == 4 && std::memcmp(m, kZstdMagic, 4) == 0;
}

ByteSource::ByteSource(const std::string& path) : path_(path) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) throw IoError(system_error_text(path, "cannot open", errno));
  struct stat st;
  if (::fstat(fd_, &st) != 0) {
    int e = errno;
    ::close(fd_);
    throw IoError(system_error_text(path, "cannot stat", e));
  }
  if (S_ISDIR(st.st_mode)) {
    ::close(fd_);
    throw IoError(path + ": is a directory");
  }
  file_size_ = std::uint64_t(st.st_size);
  ::posix_fadvise(fd_, 0, 0, POSIX_FADV_SEQUENTIAL);
  buf_.resize(kBufferSize);
  if (is_zstd_file(path)) {
    zstd_ = ZSTD_createDCtx();
    if (!zstd_) throw IoError(path + ": cannot create a zstd decompression context");
    zin_.resize(ZSTD_DStreamInSize());
  }
}

ByteSource::~ByteSource() {
  if (zstd_) ZSTD_freeDCtx(zstd_);
  if (fd_ >= 0) ::close(fd_);
}

std::size_t ByteSource::fill_raw(unsigned char* dst, std::size_t cap) {
  if (!zstd_) {
    std::size_t got = 0;
    while (got < cap) {
      ssize_t n = ::read(fd_, dst + got, cap - got);
      if (n < 0) {
        if (errno == EINTR) continue;
        throw IoError(system_error_text(path_, "read failed", errno));
      }
      if (n == 0) break;
      got += std::size_t(n);
      raw_consumed_ += std::uint64_t(n);
    }
    return got;
  }
  ZSTD_outBuffer out{dst, cap, 0};
  while (out.pos < out.size) {
    if (zin_pos_ == zin_end_) {
      if (raw_eof_) break;
      ssize_t n;
      do n = ::read(fd_, zin_.data(), zin_.size());
      while (n < 0 && errno == EINTR);
      if (n < 0) throw IoError(system_error_text(path_, "read failed", errno));
      if (n == 0) {
        raw_eof_ = true;
        if (!frame_done_)
          throw InputError(at_byte(path_, raw_consumed_, "truncated zstd stream (compressed offset)"));
        break;
      }
      raw_consumed_ += std::uint64_t(n);
      zin_pos_ = 0;
      zin_end_ = std::size_t(n);
    }
    ZSTD_inBuffer in{zin_.data(), zin_end_, zin_pos_};
    std::size_t r = ZSTD_decompressStream(zstd_, &out, &in);
    zin_pos_ = in.pos;
    if (ZSTD_isError(r))
      throw InputError(at_byte(path_, raw_consumed_ - (zin_end_ - zin_pos_),
                               std::string("corrupt zstd stream: ") + ZSTD_getErrorName(r)));
    frame_done_ = (r == 0);
  }
  return out.pos;
}

bool ByteSource::refill_for(std::size_t n) {
  if (n > buf_.size()) buf_.resize(n);
  // Move the unread tail to the front, then fill the rest.
  if (pos_ > 0) {
    std::memmove(buf_.data(), buf_.data() + pos_, end_ - pos_);
    base_ += pos_;
    end_ -= pos_;
    pos_ = 0;
  }
  while (end_ - pos_ < n && !eof_) {
    std::size_t got = fill_raw(buf_.data() + end_, buf_.size() - end_);
    if (got == 0) eof_ = true;
    end_ += got;
  }
  return end_ - pos_ >= n;
}

void ByteSource::read_exact(void* dst, std::size_t n, const char* what) {
  auto* d = static_cast<unsigned char*>(dst);
  while (n > 0) {
    std::size_t chunk = n < kMaxPeek ? n : kMaxPeek;
    const unsigned char* p = peek(chunk);
    if (!p) throw InputError(at_byte(path_, offset(), std::string("unexpected end of file reading ") + what));
    std::memcpy(d, p, chunk);
    consume(chunk);
    d += chunk;
    n -= chunk;
  }
}

void ByteSource::skip(std::uint64_t n, const char* what) {
  std::uint64_t in_buffer = end_ - pos_;
  if (n <= in_buffer) {
    pos_ += std::size_t(n);
    return;
  }
  if (!zstd_) {
    // Compared as a difference: offset() + n may wrap around 2^64 (n comes from
    // counts in the file) and would then seek backwards.
    if (offset() > file_size_ || n > file_size_ - offset())
      throw InputError(at_byte(path_, file_size_, std::string("unexpected end of file reading ") + what));
    std::uint64_t target = offset() + n;
    if (::lseek(fd_, off_t(target), SEEK_SET) < 0) throw IoError(system_error_text(path_, "seek failed", errno));
    raw_consumed_ = target;
    base_ = target;
    pos_ = end_ = 0;
    eof_ = false;
    return;
  }
  while (n > 0) {
    std::size_t chunk = n < kMaxPeek ? std::size_t(n) : kMaxPeek;
    if (!peek(chunk)) throw InputError(at_byte(path_, offset(), std::string("unexpected end of file reading ") + what));
    consume(chunk);
    n -= chunk;
  }
}

bool ByteSource::at_end() { return peek(1) == nullptr; }

bool ByteSource::next_line(std::string_view* line) {
  std::size_t scanned = 0;  // bytes after pos_ known to hold no '\n'
  for (;;) {
    const unsigned char* start = buf_.data() + pos_ + scanned;
    const void* nl = std::memchr(start, '\n', end_ - pos_ - scanned);
    if (nl) {
      std::size_t len = std::size_t(static_cast<const unsigned char*>(nl) - (buf_.data() + pos_));
      const char* s = reinterpret_cast<const char*>(buf_.data() + pos_);
      pos_ += len + 1;
      if (len > 0 && s[len - 1] == '\r') --len;
      *line = std::string_view(s, len);
      ++line_;
      return true;
    }
    scanned = end_ - pos_;
    if (eof_) break;
    // Grow when the partial line fills the buffer, so lines of any length work.
    if (pos_ == 0 && end_ == buf_.size()) buf_.resize(buf_.size() * 2);
    std::size_t before = end_ - pos_;
    refill_for(before + 1);
    if (end_ - pos_ == before) eof_ = true;
  }
  if (end_ == pos_) return false;
  std::size_t len = end_ - pos_;
  const char* s = reinterpret_cast<const char*>(buf_.data() + pos_);
  pos_ = end_;
  if (len > 0 && s[len - 1] == '\r') --len;
  *line = std::string_view(s, len);
  ++line_;
  return true;
}

}  // namespace oocsimp
