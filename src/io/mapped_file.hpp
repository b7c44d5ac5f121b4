// Memory mapping of a whole file, read-only unless asked otherwise.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace oocsimp {

enum class MapAccess { read, read_write };

class MappedFile {
 public:
  /// Maps `path` (shared: writes go to the file); throws IoError. An empty file maps
  /// to data() == nullptr.
  explicit MappedFile(const std::string& path, MapAccess access = MapAccess::read);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  const unsigned char* data() const { return data_; }
  /// The mapping for writing; only for MapAccess::read_write.
  unsigned char* writable_data() { return data_; }
  std::uint64_t size() const { return size_; }

 private:
  unsigned char* data_ = nullptr;
  std::uint64_t size_ = 0;
};

}  // namespace oocsimp
