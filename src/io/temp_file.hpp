// oocsimp — temporary files that never outlive a run.
//
// Every temporary file is registered in a process-wide table; it is deleted when its
// owner goes away, and by the signal handlers that install_signal_cleanup() sets up,
// which unlink every registered path before the process dies.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "oocsimp/process.hpp"

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

/// A temporary file in the folder of `dest`, named ".NAME.tmp-XXXXXX" after it (NAME cut
/// to its first 24 bytes, so that a 255-byte output name still has a valid temporary
/// name), for writing an output that commit(dest) then renames into place.
std::unique_ptr<TempFile> temp_file_beside(const std::string& dest);

/// An output destination named by the user (-o, --stats), opened before the work starts.
/// A regular file, or a name that does not exist yet, is written under a temporary name
/// beside it and renamed into place by commit(): a failed run leaves it untouched. A
/// symbolic link is followed and its target written that way (the link stays). A device,
/// FIFO or socket is opened and written directly, and "-" is stdout: there is nothing to
/// replace, and replacing /dev/null or a FIFO would be wrong.
class OutputFile {
 public:
  /// Throws IoError (missing folder, permissions, a folder named as the output).
  explicit OutputFile(const std::string& path);
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  /// Removes the temporary file when commit() was not reached.
  ~OutputFile();

  /// The name as given, for messages.
  const std::string& path() const { return path_; }
  /// Where the bytes go (not owned by the caller).
  int fd() const;
  /// True for stdout, devices, FIFOs and sockets: written in place, commit() renames nothing.
  bool streamed() const { return temp_ == nullptr; }
  /// Writes all of `bytes`. Throws IoError.
  void write_all(const std::string& bytes);
  /// Puts the finished output in place. Throws IoError.
  void commit();

 private:
  std::string path_;
  std::string target_;  // path_ with its links followed
  std::unique_ptr<TempFile> temp_;
  int fd_ = -1;
  bool owns_fd_ = false;
};

/// `path` with symbolic links followed to the final target, which need not exist.
/// Throws IoError on a loop of links.
std::string resolve_links(const std::string& path);

/// True when `a` and `b` name the same file: the same device and inode, or, when neither
/// exists yet, the same name once links and the folder are resolved. "-" (stdin or
/// stdout) is never the same as anything here; callers compare it by name.
bool same_file(const std::string& a, const std::string& b);

/// Writes `content` to `path` as an OutputFile. Throws IoError.
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

}  // namespace oocsimp
