#include "spill/stream_spill.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zstd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "io/error_text.hpp"
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
  std::uint64_t previous;      // offset of the stream's previous block, or kNoBlock
  std::uint32_t raw_bytes;     // payload size before compression
  std::uint32_t stored_bytes;  // payload size on disk (== raw_bytes: stored raw)
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

// From this allowance on the memory blocks lie on huge pages (MemorySlabs): the
// huge page faulted in ahead is then at most a thirty-second of it.
constexpr std::uint64_t kHugeSlabAllowance = std::uint64_t(64) << 20;

struct StreamSpill::Stream {
  unsigned char* buffer = nullptr;  // in buffers_, once the stream has had a record
  std::size_t buffered = 0;         // records in buffer
  // Blocks kept in memory (in memory_), in append order, as (where, bytes): the
  // first records of the stream.
  std::vector<std::pair<const unsigned char*, std::size_t>> memory;
  std::uint64_t memory_bytes = 0;  // record bytes in `memory`
  bool to_disk = false;            // a block went to the file: every later one does too
  std::uint64_t last_block = kNoBlock;
  std::uint64_t records = 0;
  std::mutex mutex;  // guards everything above for this stream
};

StreamSpill::StreamSpill(const std::string& temp_dir, const std::string& name, std::size_t record_size,
                         std::size_t buffer_records, bool compress, std::uint64_t memory_allowance)
    : path_(temp_dir + "/oocsimp-" + name + "-"),
      dir_(temp_dir),
      name_(name),
      record_size_(record_size),
      buffer_records_(buffer_records < 1 ? 1 : buffer_records),
      compress_(compress),
      memory_allowance_(memory_allowance),
      memory_(true, memory_allowance >= kHugeSlabAllowance) {
  // Without an allowance every block goes to the file: create it now, so that a
  // folder that cannot hold it is reported before any work.
  if (memory_allowance_ == 0) create_file();
}

StreamSpill::StreamSpill(std::size_t record_size) : record_size_(record_size), buffer_records_(1), compress_(false) {}

StreamSpill::~StreamSpill() {
  if (!file_ && fd_ >= 0) ::close(fd_);
}

void StreamSpill::create_file() {
  if (file_ || fd_ >= 0) return;
  file_ = std::make_unique<TempFile>(dir_, "oocsimp-" + name_ + "-");
  fd_ = file_->fd();
  path_ = file_->path();
}

const std::string& StreamSpill::path() const { return path_; }

StreamSpill::Chain StreamSpill::chain(std::uint32_t stream) const {
  return {streams_[stream]->last_block, streams_[stream]->records};
}

void StreamSpill::keep_as(const std::string& path) {
  flush();
  bool in_memory;
  {
    std::lock_guard<std::mutex> lock(write_mutex_);
    in_memory = memory_held_ > 0;
  }
  if (in_memory) rewrite_with_memory_blocks();
  {
    std::lock_guard<std::mutex> lock(write_mutex_);
    create_file();  // an empty spill is kept as an empty file
  }
  file_->persist(path);
  path_ = path;
}

// keep_as with blocks in memory: a stream's memory blocks come before its disk
// blocks, and a chain must run backwards through the file (read_into checks that),
// so every stream is written again into a fresh file, its blocks in order: memory
// blocks as they are, disk blocks copied as stored (compressed or not).
void StreamSpill::rewrite_with_memory_blocks() {
  auto fresh = std::make_unique<TempFile>(dir_, "oocsimp-" + name_ + "-");
  std::uint64_t end = 0;
  std::vector<unsigned char> stored;
  for (auto& tp : streams_) {
    Stream& t = *tp;
    std::lock_guard<std::mutex> lock(t.mutex);
    std::uint64_t previous = kNoBlock;
    for (const auto& [data, size] : t.memory)
      previous = write_disk_block(fresh->fd(), &end, previous, pack(data, size), size);
    // The disk blocks, found backwards from the last one, then copied in order.
    std::vector<std::uint64_t> chain;
    for (std::uint64_t b = t.last_block; b != kNoBlock;) {
      BlockHeader h;
      if (b >= end_ || (!chain.empty() && b >= chain.back()))
        throw IoError(path_ + ": byte " + std::to_string(b) + ": corrupt tile spill chain");
      pread_all(fd_, &h, sizeof h, b, path_);
      chain.push_back(b);
      b = h.previous;
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      BlockHeader h;
      pread_all(fd_, &h, sizeof h, *it, path_);
      if (h.stored_bytes > end_ - *it - sizeof h)
        throw IoError(path_ + ": byte " + std::to_string(*it) + ": corrupt tile spill block");
      stored.resize(h.stored_bytes);
      pread_all(fd_, stored.data(), h.stored_bytes, *it + sizeof h, path_);
      h.previous = previous;
      previous = end;
      write_at(fresh->fd(), &h, sizeof h, end);
      write_at(fresh->fd(), stored.data(), stored.size(), end + sizeof h);
      end += sizeof h + stored.size();
    }
    t.last_block = previous;
    std::vector<std::pair<const unsigned char*, std::size_t>>().swap(t.memory);
    t.memory_bytes = 0;
    t.to_disk = true;
  }
  std::lock_guard<std::mutex> lock(write_mutex_);
  file_ = std::move(fresh);
  fd_ = file_->fd();
  path_ = file_->path();
  end_ = end;
  memory_held_ = 0;
  memory_.release();
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
    t->to_disk = true;
    f->streams_.push_back(std::move(t));
  }
  return f;
}

std::uint32_t StreamSpill::add_stream() {
  streams_.push_back(std::make_unique<Stream>());
  return std::uint32_t(streams_.size() - 1);
}

void StreamSpill::renumber_streams(const std::vector<std::uint32_t>& old_of_new) {
  std::vector<std::unique_ptr<Stream>> renumbered(old_of_new.size());
  for (std::size_t i = 0; i < old_of_new.size(); ++i)
    renumbered[i] = old_of_new[i] == kNewStream ? std::make_unique<Stream>() : std::move(streams_.at(old_of_new[i]));
  streams_ = std::move(renumbered);
}

bool StreamSpill::reserve_memory(std::size_t bytes) {
  std::lock_guard<std::mutex> lock(write_mutex_);
  if (memory_held_ + bytes > memory_allowance_) return false;
  memory_held_ += bytes;
  return true;
}

void StreamSpill::write_at(int fd, const void* data, std::size_t n, std::uint64_t offset) const {
  auto* p = static_cast<const unsigned char*>(data);
  while (n > 0) {
    ssize_t w = ::pwrite(fd, p, n, off_t(offset));
    if (w < 0 && errno == EINTR) continue;
    if (w < 0) {
      int e = errno;
      std::string need = expected_bytes_ ? "; the run's spill needs about " + mib_text(expected_bytes_) : "";
      throw IoError(dir_ + ": cannot write the tile spill file " + path_ + " (" + mib_text(offset) + " written" + need +
                    "): " + std::strerror(e));
    }
    p += w;
    n -= std::size_t(w);
    offset += std::uint64_t(w);
  }
}

// The payload of a block on disk: `raw` itself, or its zstd compression (in this
// thread's buffer) when compress_ is set and that is smaller.
std::pair<const void*, std::size_t> StreamSpill::pack(const void* raw, std::size_t raw_bytes) const {
  if (compress_) {
    ZstdContexts& zc = zstd_contexts();
    std::vector<unsigned char>& packed = zc.packed;
    packed.resize(ZSTD_compressBound(raw_bytes));
    std::size_t z = ZSTD_compressCCtx(zc.c, packed.data(), packed.size(), raw, raw_bytes, 1);
    if (!ZSTD_isError(z) && z < raw_bytes) return {packed.data(), z};
  }
  return {raw, raw_bytes};
}

// Writes a block of `raw_bytes` record bytes, stored as `payload`, at *end and
// advances *end; returns where the block starts.
std::uint64_t StreamSpill::write_disk_block(int fd, std::uint64_t* end, std::uint64_t previous,
                                            std::pair<const void*, std::size_t> payload, std::size_t raw_bytes) const {
  BlockHeader h{previous, std::uint32_t(raw_bytes), std::uint32_t(payload.second)};
  std::uint64_t at = *end;
  write_at(fd, &h, sizeof h, at);
  write_at(fd, payload.first, payload.second, at + sizeof h);
  *end = at + sizeof h + payload.second;
  return at;
}

void StreamSpill::write_block(Stream& t) {
  const std::size_t raw = t.buffered * record_size_;
  if (!t.to_disk && reserve_memory(raw)) {
    unsigned char* block = memory_.allocate(raw);
    std::memcpy(block, t.buffer, raw);
    t.memory.emplace_back(block, raw);
    t.memory_bytes += raw;
    t.buffered = 0;
    std::lock_guard<std::mutex> lock(write_mutex_);
    memory_appended_ += raw;
    return;
  }
  t.to_disk = true;
  const auto payload = pack(t.buffer, raw);  // outside the lock: threads compress at once
  std::lock_guard<std::mutex> lock(write_mutex_);
  create_file();
  t.last_block = write_disk_block(fd_, &end_, t.last_block, payload, raw);
  disk_appended_ += raw;
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
    if (!t.buffer) t.buffer = buffers_.allocate(buffer_records_ * record_size_);
    std::size_t k = std::min(count, buffer_records_ - t.buffered);
    std::memcpy(t.buffer + t.buffered * record_size_, p, k * record_size_);
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
    t.buffer = nullptr;
  }
  buffers_.release();
}

void StreamSpill::discard() {
  for (auto& tp : streams_) {
    Stream& t = *tp;
    std::lock_guard<std::mutex> lock(t.mutex);
    std::vector<std::pair<const unsigned char*, std::size_t>>().swap(t.memory);
    t.buffer = nullptr;
    t.buffered = 0;
  }
  buffers_.release();
  std::lock_guard<std::mutex> lock(write_mutex_);
  memory_.release();
  memory_held_ = 0;
  discarded_ = true;
}

// Fills out[begin, end) with the stream's disk blocks (the records after its memory
// blocks and before its buffer), with t.mutex held.
void StreamSpill::read_disk_part(const Stream& t, unsigned char* out, std::size_t begin, std::size_t end) const {
  ZstdContexts& zc = zstd_contexts();
  std::vector<unsigned char>& packed = zc.packed;
  // Blocks are chained backwards: fill from the end. Blocks are appended at the end
  // of the file, so a stream's previous block lies strictly before it: a chain that
  // does not go backwards (a zeroed header points to itself) is damage, and the walk
  // ends after at most one step per block.
  std::size_t pos = end;
  const std::uint64_t file_end = bytes_on_disk();
  for (std::uint64_t b = t.last_block, next_limit = file_end; b != kNoBlock;) {
    BlockHeader h;
    if (b >= next_limit || file_end - b < sizeof h)
      throw IoError(path_ + ": byte " + std::to_string(b) + ": corrupt tile spill chain");
    pread_all(fd_, &h, sizeof h, b, path_);
    if (h.raw_bytes == 0 || h.raw_bytes > pos - begin || h.stored_bytes > h.raw_bytes ||
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
  if (pos != begin) throw IoError(path_ + ": tile spill chain shorter than its record count");
}

void StreamSpill::read_into(std::uint32_t stream, void* dest, std::size_t bytes) const {
  const Stream& t = *streams_[stream];
  std::lock_guard<std::mutex> lock(const_cast<Stream&>(t).mutex);
  if (discarded_) throw std::logic_error(path_ + ": read after discard");
  if (bytes != t.records * record_size_) throw std::logic_error(path_ + ": read into a buffer of the wrong size");
  unsigned char* out = static_cast<unsigned char*>(dest);
  std::size_t pos = 0;
  for (const auto& [data, size] : t.memory) {
    std::memcpy(out + pos, data, size);
    pos += size;
  }
  const std::size_t tail = t.buffered * record_size_;
  read_disk_part(t, out, pos, bytes - tail);
  if (tail) std::memcpy(out + bytes - tail, t.buffer, tail);
}

void StreamSpill::for_each_block(std::uint32_t stream, const std::function<void(const void*, std::size_t)>& f) const {
  const Stream& t = *streams_[stream];
  std::lock_guard<std::mutex> lock(const_cast<Stream&>(t).mutex);
  if (discarded_) throw std::logic_error(path_ + ": read after discard");
  for (const auto& [data, size] : t.memory) f(data, size / record_size_);
  const std::size_t tail = t.buffered * record_size_;
  const std::size_t on_disk = std::size_t(t.records * record_size_ - t.memory_bytes - tail);
  if (on_disk) {
    std::vector<unsigned char> run(on_disk);
    read_disk_part(t, run.data(), 0, on_disk);
    f(run.data(), on_disk / record_size_);
  }
  if (tail) f(t.buffer, t.buffered);
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

std::uint64_t StreamSpill::bytes_kept_in_memory() const {
  std::lock_guard<std::mutex> lock(write_mutex_);
  return memory_appended_;
}

std::uint64_t StreamSpill::bytes_spilled() const {
  std::lock_guard<std::mutex> lock(write_mutex_);
  return disk_appended_;
}

}  // namespace oocsimp
