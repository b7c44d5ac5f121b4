#include "io/temp_file.hpp"

#include <fcntl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <vector>

#include "io/signal_cleanup.hpp"
#include "io/error_text.hpp"
#include "oocsimp/error.hpp"

namespace oocsimp {

namespace {

// The registry is a fixed table of fixed-size paths so the signal handler can walk
// it without allocating or locking (unlink is async-signal-safe).
constexpr int kSlots = 256;
constexpr std::size_t kPathMax = 4096;
char g_paths[kSlots][kPathMax];
std::atomic<bool> g_used[kSlots];
std::mutex g_mutex;

int register_path(const std::string& path) {
  if (path.size() >= kPathMax) return -1;
  std::lock_guard<std::mutex> lock(g_mutex);
  for (int i = 0; i < kSlots; ++i) {
    if (!g_used[i].load()) {
      std::memcpy(g_paths[i], path.c_str(), path.size() + 1);
      g_used[i].store(true);
      return i;
    }
  }
  return -1;
}

void unregister_path(int slot) {
  if (slot < 0) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  g_used[slot].store(false);
}

// Another thread may be between creating a file and registering it (with the
// cleanup signals blocked there, so the handler runs elsewhere). The handler first
// says it is dying, which stops new creations, then waits for those under way to be
// registered, then removes everything registered.
std::atomic<int> g_creating{0};
std::atomic<bool> g_dying{false};
// Likewise a thread renaming a finished file into place (rename_unless_interrupted):
// the handler waits for it, and it renames nothing once the handler has begun.
std::atomic<int> g_committing{0};
// Whether install_signal_cleanup() put the handlers in: only then does a pending
// cleanup signal mean this process is about to end (a program that links the library
// may take those signals itself).
std::atomic<bool> g_handlers{false};

// The signals that end a run from outside: interrupt, kill, closed terminal, quit.
constexpr int kCleanupSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};

// Async-signal-safe: no allocation, no locks.
void remove_registered_files() {
  g_dying.store(true);
  // A creation takes microseconds; the bound only guards against a thread that
  // stopped inside one (it cannot be this thread: it blocks the signals there).
  for (long spin = 0; (g_creating.load() > 0 || g_committing.load() > 0) && spin < 100000000L; ++spin) {
  }
  for (int i = 0; i < kSlots; ++i)
    if (g_used[i].load()) ::unlink(g_paths[i]);
}

// rename(from, to), unless a cleanup signal has been sent (pending) or is being
// handled: then nothing is renamed, and the thread waits for that signal to end the
// process. A run interrupted before its output is in place so never puts it there,
// whichever thread the signal reaches and however late.
int rename_unless_interrupted(const char* from, const char* to) {
  sigset_t block, old, pending;
  sigemptyset(&block);
  for (int sig : kCleanupSignals) sigaddset(&block, sig);
  pthread_sigmask(SIG_BLOCK, &block, &old);
  g_committing.fetch_add(1);
  bool interrupted = g_dying.load();
  if (!interrupted && g_handlers.load() && sigpending(&pending) == 0)
    for (int sig : kCleanupSignals) interrupted = interrupted || sigismember(&pending, sig) == 1;
  int rc = 0, err = 0;
  if (!interrupted) {
    rc = ::rename(from, to);
    err = errno;
  }
  g_committing.fetch_sub(1);
  pthread_sigmask(interrupted ? SIG_UNBLOCK : SIG_SETMASK, interrupted ? &block : &old, nullptr);
  if (interrupted)
    for (;;) ::pause();
  errno = err;
  return rc;
}

extern "C" void cleanup_and_die(int sig) {
  remove_registered_files();
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

// Memory-mapped files, for the SIGBUS handler: a read of a mapped page beyond the end
// of a file that shrank after it was mapped raises SIGBUS. Same fixed table scheme as
// the temporary files.
constexpr int kMappedSlots = 64;
struct MappedSlot {
  std::atomic<bool> used{false};
  const void* base = nullptr;
  std::size_t size = 0;
  char path[kPathMax];
};
MappedSlot g_mapped[kMappedSlots];

bool same_text(const char* a, const char* b) {
  for (; *a && *a == *b; ++a, ++b) {
  }
  return *a == *b;
}

// The path of the mapped file that holds `addr`, unless that file is one of the run's
// own temporary files; nullptr when there is none.
const char* mapped_input_at(const void* addr) {
  auto at = reinterpret_cast<std::uintptr_t>(addr);
  for (const MappedSlot& m : g_mapped) {
    auto base = reinterpret_cast<std::uintptr_t>(m.base);
    if (!m.used.load() || at < base || at - base >= m.size) continue;
    for (int i = 0; i < kSlots; ++i)
      if (g_used[i].load() && same_text(g_paths[i], m.path)) return nullptr;
    return m.path;
  }
  return nullptr;
}

void write_text(const char* s) {
  std::size_t n = 0;
  while (s[n]) ++n;
  while (n > 0) {
    ssize_t w = ::write(2, s, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return;
    s += w;
    n -= std::size_t(w);
  }
}

// A mapped input that shrank during the run is an I/O error like any other (exit 4,
// one line); any other SIGBUS is a crash, after the clean-up.
extern "C" void cleanup_after_bus_error(int sig, siginfo_t* info, void*) {
  const char* input = info && info->si_code == BUS_ADRERR ? mapped_input_at(info->si_addr) : nullptr;
  remove_registered_files();
  if (input) {
    write_text("oocsimp: ");
    write_text(input);
    write_text(": input changed during the run\n");
    ::_exit(4);
  }
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

}  // namespace

TempFile::TempFile(const std::string& dir, const std::string& prefix) {
  std::string pattern = (dir.empty() ? std::string(".") : dir) + "/" + prefix + "XXXXXX";
  std::vector<char> buf(pattern.begin(), pattern.end());
  buf.push_back('\0');
  // Block the cleanup signals between creating and registering the file, so an
  // interrupt cannot leave it behind.
  sigset_t block, old;
  sigemptyset(&block);
  for (int sig : kCleanupSignals) sigaddset(&block, sig);
  pthread_sigmask(SIG_BLOCK, &block, &old);
  g_creating.fetch_add(1);
  int err = EINTR;  // when dying: the run is being interrupted
  if (!g_dying.load()) {
    fd_ = ::mkostemp(buf.data(), O_CLOEXEC);
    err = errno;
    if (fd_ >= 0) {
      path_ = buf.data();
      slot_ = register_path(path_);
    }
  }
  g_creating.fetch_sub(1);
  pthread_sigmask(SIG_SETMASK, &old, nullptr);
  if (fd_ < 0) throw IoError(system_error_text(dir, "cannot create a temporary file in", err));
}

TempFile::~TempFile() {
  close();
  if (!path_.empty() && !persisted_) ::unlink(path_.c_str());
  unregister_path(slot_);
}

void TempFile::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void TempFile::commit(const std::string& dest) {
  // mkstemp creates 0600; a finished output gets the usual 0666 & ~umask.
  mode_t mask = ::umask(0);
  ::umask(mask);
  if (fd_ >= 0) ::fchmod(fd_, 0666 & ~mask);
  close();
  if (rename_unless_interrupted(path_.c_str(), dest.c_str()) != 0)
    throw IoError(system_error_text(dest, "cannot rename " + path_ + " to", errno));
  unregister_path(slot_);
  slot_ = -1;
  path_.clear();
}

namespace {

std::string folder_of(const std::string& path) {
  std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? "." : slash == 0 ? "/" : path.substr(0, slash);
}

std::string name_of(const std::string& path) {
  std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// A connected stream socket: open() cannot write to a Unix socket.
int connect_unix_socket(const std::string& path) {
  sockaddr_un addr;
  std::memset(&addr, 0, sizeof addr);
  addr.sun_family = AF_UNIX;
  if (path.size() >= sizeof addr.sun_path) {
    errno = ENAMETOOLONG;
    return -1;
  }
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    int err = errno;
    ::close(fd);
    errno = err;
    return -1;
  }
  return fd;
}

void write_fd_all(int fd, const std::string& path, const std::string& content) {
  const char* p = content.data();
  std::size_t n = content.size();
  while (n > 0) {
    ssize_t w = ::write(fd, p, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      throw IoError(system_error_text(path, "write failed", errno));
    }
    p += w;
    n -= std::size_t(w);
  }
}

}  // namespace

std::unique_ptr<TempFile> temp_file_beside(const std::string& dest) {
  constexpr std::size_t kNameBytes = 24;  // ".NAME.tmp-XXXXXX" stays far below NAME_MAX
  return std::make_unique<TempFile>(folder_of(dest), "." + name_of(dest).substr(0, kNameBytes) + ".tmp-");
}

std::string resolve_links(const std::string& path) {
  std::string p = path;
  for (int hops = 0; hops < 40; ++hops) {  // 40: the kernel's own limit (MAXSYMLINKS)
    struct stat st;
    if (::lstat(p.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return p;
    std::vector<char> buf(std::size_t(st.st_size > 0 ? st.st_size : 4096) + 1);
    ssize_t n = ::readlink(p.c_str(), buf.data(), buf.size());
    if (n < 0 || std::size_t(n) >= buf.size()) throw IoError(system_error_text(path, "cannot read the link", errno));
    std::string target(buf.data(), std::size_t(n));
    p = !target.empty() && target[0] == '/' ? target : folder_of(p) + "/" + target;
  }
  throw IoError(system_error_text(path, "cannot follow the links", ELOOP));
}

bool same_file(const std::string& a, const std::string& b) {
  if (a == "-" || b == "-") return false;
  struct stat sa, sb;
  bool ea = ::stat(a.c_str(), &sa) == 0, eb = ::stat(b.c_str(), &sb) == 0;
  if (ea || eb) return ea && eb && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
  // Neither exists yet: the same folder (resolved) and the same name.
  auto canonical = [](const std::string& p) {
    std::string t = resolve_links(p);
    char* dir = ::realpath(folder_of(t).c_str(), nullptr);
    if (!dir) return t;
    std::string r = std::string(dir) + "/" + name_of(t);
    std::free(dir);
    return r;
  };
  return canonical(a) == canonical(b);
}

OutputFile::OutputFile(const std::string& path) : path_(path) {
  if (path == "-") {
    fd_ = STDOUT_FILENO;
    return;
  }
  target_ = resolve_links(path);
  struct stat st;
  if (::stat(target_.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    if (S_ISDIR(st.st_mode)) throw IoError(system_error_text(path, "cannot write the output", EISDIR));
    fd_ =
        S_ISSOCK(st.st_mode) ? connect_unix_socket(target_) : ::open(target_.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY);
    if (fd_ < 0) throw IoError(system_error_text(path, "cannot open the output", errno));
    owns_fd_ = true;
    return;
  }
  temp_ = temp_file_beside(target_);
}

OutputFile::~OutputFile() {
  if (owns_fd_) ::close(fd_);
}

int OutputFile::fd() const { return temp_ ? temp_->fd() : fd_; }

void OutputFile::write_all(const std::string& bytes) { write_fd_all(fd(), path_, bytes); }

void OutputFile::commit() {
  if (temp_) {
    temp_->commit(target_);
    temp_.reset();
    fd_ = -1;
  }
}

void write_file_atomically(const std::string& path, const std::string& content) {
  OutputFile out(path);
  out.write_all(content);
  out.commit();
}

void TempFile::persist(const std::string& dest) {
  if (rename_unless_interrupted(path_.c_str(), dest.c_str()) != 0)
    throw IoError(system_error_text(dest, "cannot rename " + path_ + " to", errno));
  unregister_path(slot_);
  slot_ = -1;
  path_ = dest;
  persisted_ = true;
}

std::uint64_t free_bytes(const std::string& dir) {
  struct statvfs fs;
  if (::statvfs(dir.empty() ? "." : dir.c_str(), &fs) != 0) return ~std::uint64_t(0);
  return std::uint64_t(fs.f_bavail) * std::uint64_t(fs.f_frsize);
}

std::string mib_text(std::uint64_t bytes) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.1f MiB", double(bytes) / 1048576.0);
  return buf;
}

void require_free_space(const std::string& dir, std::uint64_t bytes, const std::string& what) {
  std::uint64_t free = free_bytes(dir);
  if (free >= bytes) return;
  throw IoError(dir + ": " + what + " needs about " + mib_text(bytes) + ", but only " + mib_text(free) +
                " are free (options.temp_dir chooses the folder)");
}

void install_signal_cleanup() {
  ::signal(SIGXFSZ, SIG_IGN);
  ::signal(SIGPIPE, SIG_IGN);
  struct sigaction sa;
  std::memset(&sa, 0, sizeof sa);
  sa.sa_handler = cleanup_and_die;
  sigemptyset(&sa.sa_mask);
  for (int sig : kCleanupSignals) sigaction(sig, &sa, nullptr);
  g_handlers.store(true);
  struct sigaction bus;
  std::memset(&bus, 0, sizeof bus);
  bus.sa_sigaction = cleanup_after_bus_error;
  bus.sa_flags = SA_SIGINFO;
  sigemptyset(&bus.sa_mask);
  sigaction(SIGBUS, &bus, nullptr);
}

int register_mapping(const void* base, std::size_t size, const std::string& path) {
  if (path.size() >= kPathMax) return -1;
  std::lock_guard<std::mutex> lock(g_mutex);
  for (int i = 0; i < kMappedSlots; ++i) {
    MappedSlot& m = g_mapped[i];
    if (m.used.load()) continue;
    m.base = base;
    m.size = size;
    std::memcpy(m.path, path.c_str(), path.size() + 1);
    m.used.store(true);
    return i;
  }
  return -1;
}

void unregister_mapping(int slot) {
  if (slot < 0) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  g_mapped[slot].used.store(false);
}

}  // namespace oocsimp
