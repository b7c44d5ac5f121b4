#include "spill/stream_spill.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zstd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {

constexpr std::uint64_t kNoBlock = ~std::uint64_t(0);

// zstd contexts, one per thread and kept: ZSTD_compress and ZSTD_decompress would
// allocate (and, above the mmap threshold, map and unmap) a context per block.
struct ZstdContexts {
  ZSTD_CCtx* c = ZSTD_createCCtx();
  ZSTD_DCtx* d = ZSTD_createDCtx();
  std::vector<unsigned char> packed;  // a compressed block
  ~ZstdContexts() {
    ZSTD_freeCCtx(c);
    ZSTD_freeDCtx(d);
  }
};
ZstdContexts& zstd_contexts() {
  thread_local ZstdContexts z;
  return z;
}

// On disk, each block is this header followed by its payload.
struct BlockHeader {
  std::uint64_t previous;     // offset of the stream's previous block, or kNoBlock
  std::uint32_t raw_bytes;    // payload size before compression
  std::uint32_t stored_bytes; // payload size on disk (== raw_bytes: stored raw)
};

void pread_all(int fd, void* dst, std::size_t n, std::uint64_t offset, const std::string& path) {
  auto* p = static_cast<unsigned char*>(dst);
  while (n > 0) {
    ssize_t r = ::pread(fd, p, n, off_t(offset));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) throw IoError(system_error_text(path, "spill read failed", r < 0 ? errno : EIO));
    p += r;
    n -= std::size_t(r);
    offset += std::uint64_t(r);
  }
}

}  // namespace

struct StreamSpill::Stream {
  std::vector<unsigned char> buffer;
  std::size_t buffered = 0;  // records in buffer
  std::uint64_t last_block = kNoBlock;
  std::uint64_t records = 0;
  std::mutex mutex;  // guards buffer, buffered and records for this stream
};

StreamSpill::StreamSpill(const std::string& temp_dir, const std::string& name, std::size_t record_size,
                             std::size_t buffer_records, bool compress)
    : file_(std::make_unique<TempFile>(temp_dir, "oocsimp-" + name + "-")),
      fd_(file_->fd()),
      path_(file_->path()),
      dir_(temp_dir),
      record_size_(record_size),
      buffer_records_(buffer_records < 1 ? 1 : buffer_records),
      compress_(compress) {}

StreamSpill::StreamSpill(std::size_t record_size)
    : record_size_(record_size), buffer_records_(1), compress_(false) {}

StreamSpill::~StreamSpill() {
  if (!file_ && fd_ >= 0) ::close(fd_);
}

const std::string& StreamSpill::path() const { return path_; }

StreamSpill::Chain StreamSpill::chain(std::uint32_t stream) const {
  return {streams_[stream]->last_block, streams_[stream]->records};
}

void StreamSpill::keep_as(const std::string& path) {
  flush();
  file_->persist(path);
  path_ = path;
}

std::unique_ptr<StreamSpill> StreamSpill::open_kept(const std::string& path, std::size_t record_size,
                                                        const std::vector<Chain>& chains) {
  std::unique_ptr<StreamSpill> f(new StreamSpill(record_size));
  f->fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (f->fd_ < 0) throw IoError(system_error_text(path, "cannot open kept tiles", errno));
  f->path_ = path;
  struct stat st;
  if (::fstat(f->fd_, &st) != 0) throw IoError(system_error_text(path, "cannot stat kept tiles", errno));
  f->end_ = std::uint64_t(st.st_size);
  for (const Chain& c : chains) {
    auto t = std::make_unique<Stream>();
    t->last_block = c.last_block;
    t->records = c.records;
    f->streams_.push_back(std::move(t));
  }
  return f;
}

std::uint32_t StreamSpill::add_stream() {
  streams_.push_back(std::make_unique<Stream>());
  return std::uint32_t(streams_.size() - 1);
}

void StreamSpill::write_block(Stream& t) {
  std::size_t raw = t.buffered * record_size_;
  const unsigned char* payload = t.buffer.data();
  std::size_t stored = raw;
  if (compress_) {
    ZstdContexts& zc = zstd_contexts();
    std::vector<unsigned char>& packed = zc.packed;
    packed.resize(ZSTD_compressBound(raw));
    std::size_t z = ZSTD_compressCCtx(zc.c, packed.data(), packed.size(), t.buffer.data(), raw, 1);
    if (!ZSTD_isError(z) && z < raw) {
      payload = packed.data();
      stored = z;
    }
  }
  std::lock_guard<std::mutex> lock(write_mutex_);
  BlockHeader h{t.last_block, std::uint32_t(raw), std::uint32_t(stored)};
  std::uint64_t at = end_;
  auto write_at = [&](const void* data, std::size_t n, std::uint64_t offset) {
    auto* p = static_cast<const unsigned char*>(data);
    while (n > 0) {
      ssize_t w = ::pwrite(fd_, p, n, off_t(offset));
      if (w < 0 && errno == EINTR) continue;
      if (w < 0) {
        int e = errno;
        std::string need = expected_bytes_ ? "; the run's spill needs about " + mib_text(expected_bytes_) : "";
        throw IoError(dir_ + ": cannot write the tile spill file " + path_ + " (" + mib_text(end_) + " written" + need +
                      "): " + std::strerror(e));
      }
      p += w;
      n -= std::size_t(w);
      offset += std::uint64_t(w);
    }
  };
  write_at(&h, sizeof h, at);
  write_at(payload, stored, at + sizeof h);
  end_ = at + sizeof h + stored;
  t.last_block = at;
  t.buffered = 0;
}

void StreamSpill::append(std::uint32_t stream, const void* records, std::size_t count) {
  Stream& t = *streams_[stream];
  std::lock_guard<std::mutex> lock(t.mutex);
  auto* p = static_cast<const unsigned char*>(records);
  t.records += count;
  {
    std::lock_guard<std::mutex> g(write_mutex_);
    appended_ += count * record_size_;
  }
  while (count > 0) {
    if (t.buffer.empty()) t.buffer.resize(buffer_records_ * record_size_);
    std::size_t k = std::min(count, buffer_records_ - t.buffered);
    std::memcpy(t.buffer.data() + t.buffered * record_size_, p, k * record_size_);
    t.buffered += k;
    p += k * record_size_;
    count -= k;
    if (t.buffered == buffer_records_) write_block(t);
  }
}

void StreamSpill::flush() {
  for (auto& tp : streams_) {
    Stream& t = *tp;
    std::lock_guard<std::mutex> lock(t.mutex);
    if (t.buffered > 0) write_block(t);
    std::vector<unsigned char>().swap(t.buffer);
  }
}

void StreamSpill::read_into(std::uint32_t stream, void* dest, std::size_t bytes) const {
  const Stream& t = *streams_[stream];
  std::lock_guard<std::mutex> lock(const_cast<Stream&>(t).mutex);
  if (bytes != t.records * record_size_) throw std::logic_error(path_ + ": read into a buffer of the wrong size");
  unsigned char* out = static_cast<unsigned char*>(dest);
  // Blocks are chained backwards: fill the output from its end.
  std::size_t tail = t.buffered * record_size_;
  std::size_t pos = bytes - tail;
  if (tail) std::memcpy(out + pos, t.buffer.data(), tail);
  ZstdContexts& zc = zstd_contexts();
  std::vector<unsigned char>& packed = zc.packed;
  // Blocks are appended at the end of the file, so a stream's previous block lies
  // strictly before it: a chain that does not go backwards (a zeroed header points
  // to itself) is damage, and the walk ends after at most one step per block.
  const std::uint64_t file_end = bytes_on_disk();
  for (std::uint64_t b = t.last_block, next_limit = file_end; b != kNoBlock;) {
    BlockHeader h;
    if (b >= next_limit || file_end - b < sizeof h)
      throw IoError(path_ + ": byte " + std::to_string(b) + ": corrupt tile spill chain");
    pread_all(fd_, &h, sizeof h, b, path_);
    if (h.raw_bytes == 0 || h.raw_bytes > pos || h.stored_bytes > h.raw_bytes ||
        h.stored_bytes > file_end - b - sizeof h)
      throw IoError(path_ + ": byte " + std::to_string(b) + ": corrupt tile spill block");
    next_limit = b;
    pos -= h.raw_bytes;
    if (h.stored_bytes == h.raw_bytes) {
      pread_all(fd_, out + pos, h.raw_bytes, b + sizeof h, path_);
    } else {
      packed.resize(h.stored_bytes);
      pread_all(fd_, packed.data(), h.stored_bytes, b + sizeof h, path_);
      std::size_t r = ZSTD_decompressDCtx(zc.d, out + pos, h.raw_bytes, packed.data(), h.stored_bytes);
      if (ZSTD_isError(r) || r != h.raw_bytes)
        throw IoError(path_ + ": byte " + std::to_string(b) + ": corrupt compressed tile spill block");
    }
    b = h.previous;
  }
  if (pos != 0) throw IoError(path_ + ": tile spill chain shorter than its record count");
}

std::uint64_t StreamSpill::record_count(std::uint32_t stream) const { return streams_[stream]->records; }

std::uint64_t StreamSpill::bytes_on_disk() const {
  std::lock_guard<std::mutex> lock(write_mutex_);
  return end_;
}

std::uint64_t StreamSpill::bytes_appended() const {
  std::lock_guard<std::mutex> lock(write_mutex_);
  return appended_;
}

}  // namespace oocsimp
