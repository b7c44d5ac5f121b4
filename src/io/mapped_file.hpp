// Memory mapping of a whole file, read-only unless asked otherwise.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "io/temp_file.hpp"

namespace oocsimp {

enum class MapAccess { read, read_write };

class MappedFile {
 public:
  /// Maps `path` (shared: writes go to the file); throws IoError. An empty file maps
  /// to data() == nullptr. A read beyond the end of a file that shrank meanwhile ends
  /// the run with exit 4, naming `path` (see install_signal_cleanup).
  explicit MappedFile(const std::string& path, MapAccess access = MapAccess::read);
  /// Maps the first `size` bytes of the open descriptor `fd` read-only (not closed, not
  /// reopened: the mapping shows the file the caller opened, even if its path now names
  /// another); `name` is for messages. Throws IoError.
  MappedFile(int fd, std::uint64_t size, const std::string& name);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  const unsigned char* data() const { return data_; }
  /// The mapping for writing; only for MapAccess::read_write.
  unsigned char* writable_data() { return data_; }
  std::uint64_t size() const { return size_; }

 private:
  void map(int fd, const std::string& name, MapAccess access);

  unsigned char* data_ = nullptr;
  std::uint64_t size_ = 0;
  int slot_ = -1;  // in the mapping table of the SIGBUS handler (signal_cleanup.hpp)
};

/// A temporary file of `bytes` zeros in `dir`, mapped for reading and writing: an array
/// per input vertex that stays out of the heap. Removed with the object; throws IoError
/// naming the file when the room cannot be made.
class MappedScratch {
 public:
  MappedScratch(const std::string& dir, const std::string& prefix, std::uint64_t bytes);
  unsigned char* data() { return map_->writable_data(); }
  const unsigned char* data() const { return map_->data(); }
  /// Grows or shrinks the file to `bytes` (new bytes are zeros) and maps it again:
  /// data() moves. Throws IoError as the constructor.
  void resize(std::uint64_t bytes);

 private:
  TempFile file_;
  std::unique_ptr<MappedFile> map_;
};

}  // namespace oocsimp
