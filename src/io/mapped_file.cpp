#include "io/mapped_file.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

#include "io/signal_cleanup.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

MappedFile::MappedFile(const std::string& path) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw IoError(system_error_text(path, "cannot open", errno));
  struct stat st;
  if (::fstat(fd, &st) != 0) {
    int e = errno;
    ::close(fd);
    throw IoError(system_error_text(path, "cannot stat", e));
  }
  size_ = std::uint64_t(st.st_size);
  if (size_ > 0) {
    void* p = ::mmap(nullptr, size_, PROT_READ, MAP_SHARED, fd, 0);
    if (p == MAP_FAILED) {
      int e = errno;
      ::close(fd);
      throw IoError(system_error_text(path, "cannot map", e));
    }
    data_ = static_cast<const unsigned char*>(p);
    slot_ = register_mapping(data_, size_, path);
  }
  ::close(fd);
}

MappedFile::~MappedFile() {
  unregister_mapping(slot_);
  if (data_) ::munmap(const_cast<unsigned char*>(data_), size_);
}

}  // namespace oocsimp
