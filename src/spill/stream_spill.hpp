// Numbered append-only record streams, in memory while they fit an allowance and on
// disk beyond it: the out-of-core store behind tiled clustering. A stream holds a
// tile's triangles, or a bucket of records grouped by key (stitch corners by
// triangle index, cluster shares by centre index).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "common/huge_pages.hpp"
#include "io/temp_file.hpp"
#include "spill/memory_slabs.hpp"

namespace oocsimp {

/// Many append-only streams of fixed-size records. Each stream buffers its records;
/// a full buffer becomes a block. While the blocks held in memory stay within
/// `memory_allowance` bytes, a block is copied into memory (MemorySlabs); beyond
/// it, blocks go to the end of one temporary file, each pointing back to the
/// stream's previous block, so the file is written strictly sequentially. A stream
/// that once went to the file keeps going there, so its memory blocks are a prefix
/// of its records. The file is created only when a first block goes to it (at once
/// with no allowance). Blocks on disk are zstd-compressed when `compress` is set (a
/// block that does not shrink is stored raw); memory blocks never are. Appends and
/// reads may come from several threads.
class StreamSpill {
 public:
  /// `buffer_records`: records per buffer (and per block). `memory_allowance`: bytes
  /// of blocks held in memory at most (the buffers being filled not counted).
  StreamSpill(const std::string& temp_dir, const std::string& name, std::size_t record_size, std::size_t buffer_records,
              bool compress, std::uint64_t memory_allowance = 0);
  ~StreamSpill();

  /// Where a flushed stream's records are: its last block and its record count. With
  /// the file, this is all it takes to read the stream again (see open_kept).
  struct Chain {
    std::uint64_t last_block;
    std::uint64_t records;
  };
  Chain chain(std::uint32_t stream) const;
  /// Flushes, renames the file to `path` and keeps it after the run (for --keep-tmp).
  /// Blocks held in memory are written out first (then into a fresh file, every
  /// stream's blocks in order, since a chain must run backwards through the file)
  /// and freed. Throws IoError.
  void keep_as(const std::string& path);
  /// Opens a file written by keep_as, read-only, with the chains of its streams.
  /// Throws IoError.
  static std::unique_ptr<StreamSpill> open_kept(const std::string& path, std::size_t record_size,
                                                const std::vector<Chain>& chains);

  /// What the whole spill of the run is estimated to need, for the message of a write
  /// that fails (0: unknown).
  void set_expected_bytes(std::uint64_t bytes) { expected_bytes_ = bytes; }

  /// Adds an empty stream and returns its id (0, 1, 2, ...).
  std::uint32_t add_stream();
  std::uint32_t stream_count() const { return std::uint32_t(streams_.size()); }
  /// Renumbers the streams: stream i becomes the one that was `old_of_new[i]`, or a
  /// new empty one where that is kNewStream. A stream left out is dropped. Not
  /// while another thread appends or reads.
  static constexpr std::uint32_t kNewStream = ~std::uint32_t(0);
  void renumber_streams(const std::vector<std::uint32_t>& old_of_new);
  /// Appends `count` records to stream `stream`. Throws IoError (naming the folder and
  /// the bytes written so far) when the disk is full.
  void append(std::uint32_t stream, const void* records, std::size_t count);
  /// Writes every partly filled buffer to disk and frees the buffers, not while
  /// another thread appends; append() may still be called afterwards (buffers are
  /// recreated on demand).
  void flush();
  /// All records of `stream` in append order, into `out` (resized to the records;
  /// Record must be the record type, or bytes). Reads unflushed buffers too.
  /// Thread-safe.
  template <class Record, class Allocator>
  void read(std::uint32_t stream, std::vector<Record, Allocator>* out) const {
    const std::size_t count = std::size_t(record_count(stream) * record_size_ / sizeof(Record));
    resize_filled(out, count);
    read_into(stream, out->data(), out->size() * sizeof(Record));
  }
  /// The same into `bytes` bytes at `out` (exactly the stream's records' size).
  void read_into(std::uint32_t stream, void* out, std::size_t bytes) const;
  /// Calls f(records, count) for the stream's records in append order, a run at a
  /// time: memory blocks in place, without a copy; what is on disk read (and
  /// decompressed) into one temporary run first. Thread-safe (the stream is locked
  /// while f runs: f must not append to it).
  void for_each_block(std::uint32_t stream, const std::function<void(const void*, std::size_t)>& f) const;
  /// Frees every block held in memory and every buffer, for an owner done reading;
  /// the counts below stay. Reading afterwards throws std::logic_error.
  void discard();
  /// Number of records appended to `stream`.
  std::uint64_t record_count(std::uint32_t stream) const;
  /// Bytes written to the file so far.
  std::uint64_t bytes_on_disk() const;
  /// Bytes appended (before compression).
  std::uint64_t bytes_appended() const;
  /// Of those, the bytes that became blocks in memory (in all, discard() aside).
  std::uint64_t bytes_kept_in_memory() const;
  /// Of those, the bytes that became blocks on disk (before compression).
  std::uint64_t bytes_spilled() const;
  /// The file's path; before the file exists, the folder and the name's prefix.
  const std::string& path() const;

 private:
  struct Stream;
  void write_block(Stream& s);
  bool reserve_memory(std::size_t bytes);
  void create_file();  // with write_mutex_ held
  void write_at(int fd, const void* data, std::size_t n, std::uint64_t offset) const;
  std::pair<const void*, std::size_t> pack(const void* raw, std::size_t raw_bytes) const;
  std::uint64_t write_disk_block(int fd, std::uint64_t* end, std::uint64_t previous,
                                 std::pair<const void*, std::size_t> payload, std::size_t raw_bytes) const;
  void read_disk_part(const Stream& t, unsigned char* out, std::size_t begin, std::size_t end) const;
  void rewrite_with_memory_blocks();

  StreamSpill(std::size_t record_size);  // for open_kept

  std::unique_ptr<TempFile> file_;  // null for a kept file opened read-only, or until a block goes to disk
  int fd_ = -1;
  std::string path_;
  std::string dir_, name_;
  std::size_t record_size_, buffer_records_;
  bool compress_;
  std::uint64_t memory_allowance_ = 0;
  std::vector<std::unique_ptr<Stream>> streams_;
  mutable std::mutex write_mutex_;  // guards the file, its end, the memory held and the counters
  std::uint64_t end_ = 0;
  std::uint64_t appended_ = 0;
  MemorySlabs memory_;                 // the memory blocks' bytes
  std::uint64_t memory_held_ = 0;      // bytes of memory blocks now
  std::uint64_t memory_appended_ = 0;  // record bytes that went to memory blocks
  std::uint64_t disk_appended_ = 0;    // record bytes that went to disk blocks
  std::uint64_t expected_bytes_ = 0;
  // The streams' buffers, in mappings of their own for the reason MemorySlabs gives:
  // a buffer per tile, freed together by flush(), left the heap fragmented between
  // the streams' bookkeeping (about 4 KiB a tile resident after a flush and a trim).
  // Not faulted in ahead: a buffer's pages are resident only once written, as in the
  // heap, and a spill with few records holds no more than they need.
  MemorySlabs buffers_{false};
  bool discarded_ = false;
};

}  // namespace oocsimp
