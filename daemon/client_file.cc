#include "daemon/client_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace fs = std::filesystem;

namespace atelier {

std::string client_file_name(const std::string& path) {
  const std::string name = fs::path(path).filename().string();
  if (name.empty() || name == "." || name == "..")
    throw ControlError("'" + path + "' does not name a file");
  return name;
}

UniqueFd client_file(ControlRequest& request, size_t index, const std::string& path,
                     const std::string& usage) {
  if (index < request.files.size()) return std::move(request.files[index]);
  const uid_t peer = request.peer.uid;
  if (peer != ::geteuid() && peer != 0) {
    throw ControlError(request.verb + " passes the open file; use " + usage +
                       " (a raw request must pass the file's descriptor with SCM_RIGHTS: the daemon "
                       "reads no file by path for uid " + std::to_string(peer) + ")");
  }
  if (!fs::path(path).is_absolute()) throw ControlError(request.verb + " needs an absolute path");
  // Same rights as ours: opening the path ourselves reads nothing the client could not.
  // O_NONBLOCK: a FIFO must not hang the control socket (it is refused as not regular).
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
  if (fd < 0) throw ControlError(path + ": cannot open: " + std::strerror(errno));
  return UniqueFd(fd);
}

void copy_client_file(int fd, const std::string& name, const fs::path& dest, uint64_t max_bytes) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) throw ControlError(name + ": cannot read: " + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) throw ControlError(name + ": not a regular file");
  if (static_cast<uint64_t>(st.st_size) > max_bytes)
    throw ControlError(name + ": " + std::to_string(st.st_size) + " bytes is larger than the limit of " +
                       std::to_string(max_bytes) + " bytes (limits.max_file_bytes)");
  const int flags = ::fcntl(fd, F_GETFL);
  if (flags >= 0 && (flags & O_NONBLOCK)) ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
  UniqueFd out(::open(dest.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0666));
  if (!out.valid()) throw ControlError(dest.string() + ": cannot create: " + std::strerror(errno));
  std::string problem;
  uint64_t total = 0;
  char buf[1 << 16];
  for (;;) {
    ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      problem = name + ": cannot read: " + std::strerror(errno);
      break;
    }
    if (n == 0) break;
    total += static_cast<uint64_t>(n);
    if (total > max_bytes) {
      problem = name + ": grew past the limit of " + std::to_string(max_bytes) +
                " bytes (limits.max_file_bytes) while being copied";
      break;
    }
    for (ssize_t off = 0; off < n && problem.empty();) {
      ssize_t w = ::write(out.get(), buf + off, static_cast<size_t>(n - off));
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) problem = dest.string() + ": cannot write: " + std::strerror(errno);
      else off += w;
    }
    if (!problem.empty()) break;
  }
  if (problem.empty() && ::fsync(out.get()) != 0)
    problem = dest.string() + ": cannot write: " + std::strerror(errno);
  if (!problem.empty()) {
    out.reset();
    ::unlink(dest.c_str());
    throw ControlError(problem);
  }
}

}  // namespace atelier
