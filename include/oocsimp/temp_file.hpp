// oocsimp — temporary files that never outlive a run.
//
// Every temporary file is registered in a process-wide table; it is deleted when its
// owner goes away, and by the signal handlers that install_signal_cleanup() sets up,
// which unlink every registered path before the process dies.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

namespace oocsimp {

/// A uniquely named file created in `dir` (mkstemp) with the given prefix; removed
/// on destruction unless `release()` was called. Throws IoError naming the folder.
class TempFile {
 public:
  TempFile(const std::string& dir, const std::string& prefix);
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  ~TempFile();

  const std::string& path() const { return path_; }
  /// The open descriptor (read-write), owned by this object.
  int fd() const { return fd_; }
  /// Closes the descriptor (the file stays until destruction).
  void close();
  /// Renames the file to `dest` (atomic within one filesystem) and forgets it.
  /// Throws IoError.
  void commit(const std::string& dest);
  /// Renames the file to `dest` and stops tracking it (it is no longer removed at
  /// exit), keeping the descriptor open for further use. Throws IoError.
  void persist(const std::string& dest);

 private:
  std::string path_;
  int fd_ = -1;
  int slot_ = -1;
  bool persisted_ = false;
};

/// A temporary file in the folder of `dest`, named ".NAME.tmp-XXXXXX" after it, for
/// writing an output that commit(dest) then renames into place.
std::unique_ptr<TempFile> temp_file_beside(const std::string& dest);

/// Writes `content` to `path` through temp_file_beside and a rename. Throws IoError.
void write_file_atomically(const std::string& path, const std::string& content);

/// Bytes that an unprivileged writer can still put on the filesystem holding `dir`
/// (statvfs), or UINT64_MAX when that cannot be told.
std::uint64_t free_bytes(const std::string& dir);

/// Throws IoError "DIR: WHAT needs about N MiB, but only M MiB are free" when the
/// filesystem holding `dir` has less than `bytes` free: checked before a run writes
/// what it can estimate, rather than failing half-way.
void require_free_space(const std::string& dir, std::uint64_t bytes, const std::string& what);

/// `bytes` as "N.N MiB", for messages.
std::string mib_text(std::uint64_t bytes);

/// Installs SIGINT, SIGTERM, SIGHUP and SIGQUIT handlers that delete all registered
/// temporary files and then terminate the process with the conventional status
/// (128 + signal), and ignores SIGXFSZ, so that a write beyond a file-size limit
/// (ulimit -f) fails with EFBIG and the run cleans up and exits 4 instead of being
/// killed. A SIGBUS from reading a memory-mapped input that shrank during the run
/// (truncated by another process) deletes them too and exits 4 with
/// "oocsimp: FILE: input changed during the run"; any other SIGBUS is a crash after
/// the clean-up.
void install_signal_cleanup();

}  // namespace oocsimp
