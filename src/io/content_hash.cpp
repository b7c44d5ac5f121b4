#include "io/content_hash.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <vector>

#include "io/error_text.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

std::uint64_t content_hash(const void* data, std::size_t bytes) {
  ContentHash h;
  h.add(data, bytes);
  return h.digest();
}

FileDigest file_digest(const std::string& path, const std::atomic<bool>* stop) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw IoError(system_error_text(path, "cannot open", errno));
  ::posix_fadvise(fd, 0, 0, POSIX_FADV_SEQUENTIAL);
  std::vector<unsigned char> buf(std::size_t(1) << 20);
  ContentHash h;
  FileDigest d;
  while (!(stop && stop->load())) {
    ssize_t r = ::read(fd, buf.data(), buf.size());
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) {
      int e = errno;
      ::close(fd);
      throw IoError(system_error_text(path, "read failed", e));
    }
    if (r == 0) break;
    h.add(buf.data(), std::size_t(r));
    d.size += std::uint64_t(r);
  }
  ::close(fd);
  d.hash = h.digest();
  return d;
}

}  // namespace oocsimp
