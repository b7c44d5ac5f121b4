#include "io/byte_source.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "common/huge_pages.hpp"
#include "io/error_text.hpp"
#include "oocsimp/error.hpp"
#include "io/temp_file.hpp"

namespace oocsimp {

namespace {

constexpr std::size_t kBufferSize = 1 << 20;
constexpr std::size_t kCopyChunk = 1 << 18;

// The first '\n' or '\r' in [p, end), or end. Searched in short windows, so that a file
// whose lines end in a lone '\r' is not scanned ahead to the next '\n' for every line.
const unsigned char* find_line_end(const unsigned char* p, const unsigned char* end) {
  constexpr std::size_t kWindow = 256;
  while (p < end) {
    std::size_t n = std::min<std::size_t>(kWindow, std::size_t(end - p));
    const void* lf = std::memchr(p, '\n', n);
    std::size_t upto = lf ? std::size_t(static_cast<const unsigned char*>(lf) - p) : n;
    if (const void* cr = std::memchr(p, '\r', upto)) return static_cast<const unsigned char*>(cr);
    if (lf) return static_cast<const unsigned char*>(lf);
    p += n;
  }
  return end;
}

std::string size_text(std::size_t bytes) {
  return bytes % 1024 == 0 ? std::to_string(bytes / 1024) + " KiB" : std::to_string(bytes) + " bytes";
}

}  // namespace

bool starts_zstd_frame(const unsigned char* head) {
  // RFC 8878 §3.1.1 (frame magic 0xFD2FB528) and §3.1.2 (skippable frames, magic
  // 0x184D2A5?), both little-endian.
  static const unsigned char kFrame[4] = {0x28, 0xB5, 0x2F, 0xFD};
  if (std::memcmp(head, kFrame, 4) == 0) return true;
  return (head[0] & 0xF0) == 0x50 && head[1] == 0x2A && head[2] == 0x4D && head[3] == 0x18;
}

// ---------------------------------------------------------------------------------
// InputFile

std::shared_ptr<InputFile> InputFile::open(const std::string& path, const std::string& temp_dir) {
  std::shared_ptr<InputFile> f(new InputFile());
  const bool is_stdin = path == "-";
  f->name_ = is_stdin ? "stdin" : path;
  f->fd_ = is_stdin ? ::fcntl(STDIN_FILENO, F_DUPFD_CLOEXEC, 0) : ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (f->fd_ < 0) throw IoError(system_error_text(f->name_, "cannot open", errno));
  struct stat st;
  if (::fstat(f->fd_, &st) != 0) throw IoError(system_error_text(f->name_, "cannot stat", errno));
  if (S_ISDIR(st.st_mode)) throw IoError(f->name_ + ": is a directory");
  // A regular file is read where it is. Anything else (FIFO, pipe, device, socket) may
  // not be readable twice, nor from an offset; standard input redirected from a file
  // whose offset was moved is read from that offset on, so it is streamed as well.
  const bool in_place = S_ISREG(st.st_mode) && (!is_stdin || ::lseek(f->fd_, 0, SEEK_CUR) == 0);
  if (in_place) {
    f->size_ = std::uint64_t(st.st_size);
    ::posix_fadvise(f->fd_, 0, 0, POSIX_FADV_SEQUENTIAL);
  } else {
    f->copy_ = std::make_unique<TempFile>(temp_dir, "oocsimp-input-");
  }
  return f;
}

InputFile::~InputFile() {
  if (fd_ >= 0) ::close(fd_);
}

int InputFile::fd() const { return copy_ ? copy_->fd() : fd_; }

void InputFile::copy_up_to(std::uint64_t end) {
  std::vector<unsigned char> chunk;
  while (size_ < end && !stream_ended_) {
    if (chunk.empty()) chunk.resize(kCopyChunk);
    ssize_t n = ::read(fd_, chunk.data(), chunk.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      throw IoError(system_error_text(name_, "read failed", errno));
    }
    if (n == 0) {
      stream_ended_ = true;
      break;
    }
    for (std::size_t done = 0; done < std::size_t(n);) {
      ssize_t w = ::pwrite(copy_->fd(), chunk.data() + done, std::size_t(n) - done, off_t(size_ + done));
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0)
        throw IoError(system_error_text(copy_->path(), "cannot copy " + name_ + " into this temporary file",
                                        w < 0 ? errno : ENOSPC));
      done += std::size_t(w);
    }
    size_ += std::uint64_t(n);
  }
}

void InputFile::read_to_end() {
  if (copy_) copy_up_to(~std::uint64_t(0));
}

std::size_t InputFile::read_at(std::uint64_t offset, void* dst, std::size_t n) {
  if (copy_) {
    copy_up_to(offset + n);
    if (offset >= size_) return 0;
    n = std::min<std::uint64_t>(n, size_ - offset);
  }
  const int fd = this->fd();
  auto* d = static_cast<unsigned char*>(dst);
  std::size_t got = 0;
  while (got < n) {
    ssize_t r = ::pread(fd, d + got, n - got, off_t(offset + got));
    if (r < 0) {
      if (errno == EINTR) continue;
      throw IoError(system_error_text(name_, "read failed", errno));
    }
    if (r == 0) break;
    got += std::size_t(r);
  }
  return got;
}

// ---------------------------------------------------------------------------------
// ByteSource

ByteSource::ByteSource(std::shared_ptr<InputFile> file) : file_(std::move(file)) {
  unsigned char head[4];
  const bool has_head = file_->read_at(0, head, 4) == 4;
  if (has_head && starts_zstd_frame(head)) {
    zstd_ = ZSTD_createDCtx();
    if (!zstd_) throw IoError(path() + ": cannot create a zstd decompression context");
    zin_.resize(ZSTD_DStreamInSize());
  } else if (has_head && head[0] == 0x1F && head[1] == 0x8B) {  // RFC 1952 §2.3.1: ID1, ID2
    gzip_ = new z_stream_s();
    // 15 + 16: the largest window, with a gzip header and trailer.
    if (inflateInit2(gzip_, 15 + 16) != Z_OK) {
      delete gzip_;
      gzip_ = nullptr;
      throw IoError(path() + ": cannot create a gzip decompression state");
    }
    zin_.resize(1 << 17);
    frame_done_ = false;
  }
  // A small file gets a buffer of its size (peek and long lines grow it as needed):
  // clearing 1 MiB per pass would dominate reading it, a few times per input.
  std::size_t size = kBufferSize;
  if (content_size_known() && file_->size() < kBufferSize) size = std::max<std::size_t>(file_->size() + 1, 4096);
  resize_filled(&buf_, size);  // filled by the first reads
}

ByteSource::~ByteSource() {
  if (zstd_) ZSTD_freeDCtx(zstd_);
  if (gzip_) {
    inflateEnd(gzip_);
    delete gzip_;
  }
}

std::size_t ByteSource::read_raw(void* dst, std::size_t cap) {
  std::size_t got = file_->read_at(raw_consumed_, dst, cap);
  raw_consumed_ += got;
  return got;
}

// The next block of the compressed file into zin_; false at its end. A stream that
// ends inside a frame (zstd) or member (gzip) is truncated: InputError.
bool ByteSource::refill_compressed(const char* format) {
  if (raw_eof_) return false;
  const std::size_t n = read_raw(zin_.data(), zin_.size());
  if (n == 0) {
    raw_eof_ = true;
    if (!frame_done_)
      throw InputError(
          at_byte(path(), raw_consumed_, std::string("truncated ") + format + " stream (compressed offset)"));
    return false;
  }
  zin_pos_ = 0;
  zin_end_ = n;
  return true;
}

// Members follow one another (`cat a.gz b.gz`, pigz): after the end of one, the next
// must start with the gzip magic, and is inflated in turn.
std::size_t ByteSource::fill_gzip(unsigned char* dst, std::size_t cap) {
  z_stream_s& z = *gzip_;
  z.next_out = dst;
  z.avail_out = unsigned(std::min<std::size_t>(cap, 1u << 30));
  const std::size_t asked = z.avail_out;
  while (z.avail_out > 0) {
    if (zin_pos_ == zin_end_ && !refill_compressed("gzip")) break;
    if (frame_done_) {  // another member, or something that is none
      if (zin_[zin_pos_] != 0x1F)
        throw InputError(at_byte(path(), raw_consumed_ - (zin_end_ - zin_pos_),
                                 "data after the gzip stream that starts no gzip member"));
      inflateReset(&z);
      frame_done_ = false;
    }
    z.next_in = zin_.data() + zin_pos_;
    z.avail_in = unsigned(zin_end_ - zin_pos_);
    const int r = inflate(&z, Z_NO_FLUSH);
    zin_pos_ = zin_end_ - z.avail_in;
    if (r == Z_STREAM_END) {
      frame_done_ = true;
    } else if (r != Z_OK && !(r == Z_BUF_ERROR && z.avail_in == 0)) {
      throw InputError(at_byte(path(), raw_consumed_ - (zin_end_ - zin_pos_),
                               std::string("corrupt gzip stream: ") + (z.msg ? z.msg : "inflate failed")));
    }
  }
  return asked - z.avail_out;
}

std::size_t ByteSource::fill_raw(unsigned char* dst, std::size_t cap) {
  if (gzip_) return fill_gzip(dst, cap);
  if (!zstd_) return read_raw(dst, cap);
  // ZSTD_decompressStream goes on from one frame to the next and passes over skippable
  // frames, so concatenated files (`cat a.zst b.zst`, pzstd) read as `zstd -d` reads them.
  ZSTD_outBuffer out{dst, cap, 0};
  while (out.pos < out.size) {
    if (zin_pos_ == zin_end_ && !refill_compressed("zstd")) break;
    ZSTD_inBuffer in{zin_.data(), zin_end_, zin_pos_};
    std::size_t r = ZSTD_decompressStream(zstd_, &out, &in);
    zin_pos_ = in.pos;
    if (ZSTD_isError(r))
      throw InputError(at_byte(path(), raw_consumed_ - (zin_end_ - zin_pos_),
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
    if (!p) throw InputError(at_byte(path(), offset(), std::string("unexpected end of file reading ") + what));
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
  if (content_size_known()) {
    // Compared as a difference: offset() + n may wrap around 2^64 (n comes from
    // counts in the file) and would then seek backwards.
    const std::uint64_t size = file_->size();
    if (offset() > size || n > size - offset())
      throw InputError(at_byte(path(), size, std::string("unexpected end of file reading ") + what));
    std::uint64_t target = offset() + n;
    raw_consumed_ = target;
    base_ = target;
    pos_ = end_ = 0;
    eof_ = false;
    return;
  }
  while (n > 0) {
    std::size_t chunk = n < kMaxPeek ? std::size_t(n) : kMaxPeek;
    if (!peek(chunk))
      throw InputError(at_byte(path(), offset(), std::string("unexpected end of file reading ") + what));
    consume(chunk);
    n -= chunk;
  }
}

bool ByteSource::at_end() { return peek(1) == nullptr; }

void ByteSource::line_too_long(std::size_t max_length, const char* too_long) const {
  std::string what = too_long
                         ? std::string(too_long)
                         : "line longer than " + size_text(max_length) + " (binary data, or a file without line ends?)";
  throw InputError(at_line(path(), line_ + 1, what));
}

bool ByteSource::next_line(std::string_view* line, std::size_t max_length, const char* too_long) {
  std::size_t scanned = 0;  // bytes after pos_ known to hold no line end
  for (;;) {
    const unsigned char* s = buf_.data() + pos_;
    const std::size_t avail = end_ - pos_;
    const unsigned char* e = find_line_end(s + scanned, s + avail);
    const std::size_t len = std::size_t(e - s);
    // Checked as the line grows, not once it is whole: the buffer stays bounded.
    if (len > max_length) line_too_long(max_length, too_long);
    if (len < avail) {
      std::size_t ending = 1;
      if (*e == '\r') {
        if (len + 1 == avail && !eof_) {
          // A '\r' at the end of the buffered data: "\r\n" or a lone '\r'? Read on.
          scanned = len;
          if (!refill_for(avail + 1)) eof_ = true;
          continue;
        }
        if (len + 1 < avail && e[1] == '\n') ending = 2;
      }
      const bool first = offset() == 0;
      pos_ += len + ending;
      *line = std::string_view(reinterpret_cast<const char*>(s), len);
      if (first && line->substr(0, 3) == "\xEF\xBB\xBF") line->remove_prefix(3);  // UTF-8 byte order mark
      ++line_;
      return true;
    }
    scanned = avail;
    if (eof_) break;
    // Grow when the partial line fills the buffer (only for limits above its size).
    if (pos_ == 0 && end_ == buf_.size()) buf_.resize(buf_.size() * 2);
    if (!refill_for(avail + 1)) eof_ = true;
  }
  if (end_ == pos_) return false;
  const bool first = offset() == 0;
  const char* s = reinterpret_cast<const char*>(buf_.data() + pos_);
  *line = std::string_view(s, end_ - pos_);
  pos_ = end_;
  if (first && line->substr(0, 3) == "\xEF\xBB\xBF") line->remove_prefix(3);
  ++line_;
  return true;
}

}  // namespace oocsimp
