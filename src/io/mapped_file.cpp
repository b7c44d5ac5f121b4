#include "io/mapped_file.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <string>

#include "io/signal_cleanup.hpp"
#include "io/error_text.hpp"
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
  try {
    map(fd, path, access);
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
}

MappedFile::MappedFile(int fd, std::uint64_t size, const std::string& name) : size_(size) {
  map(fd, name, MapAccess::read);
}

void MappedFile::map(int fd, const std::string& name, MapAccess access) {
  if (size_ == 0) return;
  const int protection = access == MapAccess::read_write ? PROT_READ | PROT_WRITE : PROT_READ;
  void* p = ::mmap(nullptr, size_, protection, MAP_SHARED, fd, 0);
  if (p == MAP_FAILED) throw IoError(system_error_text(name, "cannot map", errno));
  data_ = static_cast<unsigned char*>(p);
  slot_ = register_mapping(data_, size_, name);
}

MappedFile::~MappedFile() {
  unregister_mapping(slot_);
  if (data_) ::munmap(data_, size_);
}

MappedScratch::MappedScratch(const std::string& dir, const std::string& prefix, std::uint64_t bytes)
    : file_(dir, prefix) {
  resize(bytes);
}

void MappedScratch::resize(std::uint64_t bytes) {
  bytes = std::max<std::uint64_t>(bytes, 8);  // an empty file would map to nothing
  const std::uint64_t before = map_ ? map_->size() : 0;
  map_.reset();
  const auto no_room = [&](int error) {
    return IoError(
        system_error_text(file_.path(), "cannot make room for " + std::to_string(bytes) + " bytes in", error));
  };
  if (::ftruncate(file_.fd(), off_t(bytes)) != 0) throw no_room(errno);
  // The blocks are taken now: a full disk is then this one error, where a page of a
  // sparse file written through the mapping would end the run with SIGBUS. A file
  // system without fallocate keeps the file sparse.
  if (bytes > before && ::fallocate(file_.fd(), 0, off_t(before), off_t(bytes - before)) != 0 && errno != EOPNOTSUPP &&
      errno != ENOSYS && errno != EINVAL)
    throw no_room(errno);
  map_ = std::make_unique<MappedFile>(file_.path(), MapAccess::read_write);
}

}  // namespace oocsimp
