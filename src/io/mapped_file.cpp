#include "io/mapped_file.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

#include "oocsimp/error.hpp"

namespace oocsimp {

MappedFile::MappedFile(const std::string& path, MapAccess access) {
  const bool write = access == MapAccess::read_write;
  int fd = ::open(path.c_str(), (write ? O_RDWR : O_RDONLY) | O_CLOEXEC);
  if (fd < 0) throw IoError(system_error_text(path, "cannot open", errno));
  struct stat st;
  if (::fstat(fd, &st) != 0) {
    int e = errno;
    ::close(fd);
    throw IoError(system_error_text(path, "cannot stat", e));
  }
  size_ = std::uint64_t(st.st_size);
  if (size_ > 0) {
    void* p = ::mmap(nullptr, size_, write ? PROT_READ | PROT_WRITE : PROT_READ, MAP_SHARED, fd, 0);
    if (p == MAP_FAILED) {
      int e = errno;
      ::close(fd);
      throw IoError(system_error_text(path, "cannot map", e));
    }
    data_ = static_cast<unsigned char*>(p);
  }
  ::close(fd);
}

MappedFile::~MappedFile() {
  if (data_) ::munmap(data_, size_);
}

}  // namespace oocsimp
