// Numbered append-only record streams on disk: the out-of-core store behind tiled
// clustering. A stream holds a tile's triangles, or a bucket of records grouped by
// key (stitch corners by triangle index, cluster shares by centre index).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "oocsimp/temp_file.hpp"

namespace oocsimp {

/// Many append-only streams of fixed-size records in one temporary file. Each
/// stream buffers its records in memory; a full buffer is written at the end of the
/// file as a block that points back to the stream's previous block, so the file is
/// written strictly sequentially and memory holds only one buffer and one block
/// offset per stream. Blocks are zstd-compressed when `compress` is set (a block that
/// does not shrink is stored raw). Appends and reads may come from several threads.
class StreamSpill {
 public:
  /// `buffer_records`: records per in-memory buffer (and per block on disk).
  StreamSpill(const std::string& temp_dir, const std::string& name, std::size_t record_size,
                std::size_t buffer_records, bool compress);
  ~StreamSpill();

  /// Where a flushed stream's records are: its last block and its record count. With
  /// the file, this is all it takes to read the stream again (see open_kept).
  struct Chain {
    std::uint64_t last_block;
    std::uint64_t records;
  };
  Chain chain(std::uint32_t stream) const;
  /// Flushes, renames the file to `path` and keeps it after the run (for --keep-tmp).
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
  /// Appends `count` records to stream `stream`. Throws IoError (naming the folder and
  /// the bytes written so far) when the disk is full.
  void append(std::uint32_t stream, const void* records, std::size_t count);
  /// Writes every partly filled buffer to disk and frees the buffers; append() may
  /// still be called afterwards (buffers are recreated on demand).
  void flush();
  /// All records of `stream` in append order, into `out` (resized to the records;
  /// Record must be the record type, or bytes). Reads unflushed buffers too.
  /// Thread-safe.
  template <class Record>
  void read(std::uint32_t stream, std::vector<Record>* out) const {
    out->resize(std::size_t(record_count(stream) * record_size_ / sizeof(Record)));
    read_into(stream, out->data(), out->size() * sizeof(Record));
  }
  /// The same into `bytes` bytes at `out` (exactly the stream's records' size).
  void read_into(std::uint32_t stream, void* out, std::size_t bytes) const;
  /// Number of records appended to `stream`.
  std::uint64_t record_count(std::uint32_t stream) const;
  /// Bytes written to the file so far.
  std::uint64_t bytes_on_disk() const;
  /// Bytes appended (before compression).
  std::uint64_t bytes_appended() const;
  const std::string& path() const;

 private:
  struct Stream;
  void write_block(Stream& s);

  StreamSpill(std::size_t record_size);  // for open_kept

  std::unique_ptr<TempFile> file_;  // null for a kept file opened read-only
  int fd_ = -1;
  std::string path_;
  std::string dir_;
  std::size_t record_size_, buffer_records_;
  bool compress_;
  std::vector<std::unique_ptr<Stream>> streams_;
  mutable std::mutex write_mutex_;  // guards the file end and stream chains
  std::uint64_t end_ = 0;
  std::uint64_t appended_ = 0;
  std::uint64_t expected_bytes_ = 0;
};

}  // namespace oocsimp
