// Read-only memory mapping of a whole file.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace oocsimp {

class MappedFile {
 public:
  /// Maps `path` read-only; throws IoError. An empty file maps to data() == nullptr.
  /// A read beyond the end of a file that shrank meanwhile ends the run with exit 4,
  /// naming `path` (see install_signal_cleanup).
  explicit MappedFile(const std::string& path);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;

  const unsigned char* data() const { return data_; }
  std::uint64_t size() const { return size_; }

 private:
  const unsigned char* data_ = nullptr;
  std::uint64_t size_ = 0;
  int slot_ = -1;  // in the mapping table of the SIGBUS handler (signal_cleanup.hpp)
};

}  // namespace oocsimp
