#include "daemon/remove_tree.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <vector>

#include "base/unique_fd.h"

namespace atelier {
namespace {

std::error_code errno_code() { return {errno, std::generic_category()}; }

// The names in the folder open at `fd` (which stays open and owned by the caller).
std::error_code list_names(int fd, std::vector<std::string>& names) {
  const int copy = ::fcntl(fd, F_DUPFD_CLOEXEC, 0);  // closedir() closes the descriptor it gets
  if (copy < 0) return errno_code();
  DIR* dir = ::fdopendir(copy);
  if (!dir) {
    const std::error_code ec = errno_code();
    ::close(copy);
    return ec;
  }
  ::rewinddir(dir);
  errno = 0;
  while (const dirent* e = ::readdir(dir)) {
    const std::string n = e->d_name;
    if (n != "." && n != "..") names.push_back(n);
    errno = 0;
  }
  const std::error_code ec = errno ? errno_code() : std::error_code{};
  ::closedir(dir);
  return ec;
}

std::error_code remove_at(int dir_fd, const std::string& name, const std::string& shown, int depth,
                          std::string& failed) {
  failed = shown;
  struct stat st;
  if (::fstatat(dir_fd, name.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0)
    return errno == ENOENT ? std::error_code{} : errno_code();
  if (!S_ISDIR(st.st_mode)) {
    if (::unlinkat(dir_fd, name.c_str(), 0) == 0 || errno == ENOENT) return {};
    if (errno != EISDIR) return errno_code();  // EISDIR: swapped for a folder meanwhile
  }
  if (depth > kMaxRemoveDepth) return {ELOOP, std::generic_category()};
  UniqueFd fd(::openat(dir_fd, name.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC));
  if (!fd.valid()) {
    if (errno == ENOENT) return {};
    // Swapped for a symlink or a file since the fstatat: remove that entry itself.
    if (errno == ELOOP || errno == ENOTDIR)
      return ::unlinkat(dir_fd, name.c_str(), 0) == 0 || errno == ENOENT ? std::error_code{} : errno_code();
    return errno_code();
  }
  std::vector<std::string> names;
  if (std::error_code ec = list_names(fd.get(), names)) return ec;
  for (const std::string& n : names)
    if (std::error_code ec = remove_at(fd.get(), n, shown + "/" + n, depth + 1, failed)) return ec;
  failed = shown;
  if (::unlinkat(dir_fd, name.c_str(), AT_REMOVEDIR) == 0 || errno == ENOENT) return {};
  return errno_code();
}

}  // namespace

std::error_code remove_tree_at(int dir_fd, const std::string& name, std::string& failed) {
  if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos) {
    failed = name;
    return {EINVAL, std::generic_category()};
  }
  return remove_at(dir_fd, name, name, 0, failed);
}

}  // namespace atelier
