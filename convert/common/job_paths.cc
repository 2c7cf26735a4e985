#include "convert/common/job_paths.h"

#include <dirent.h>
#include <fcntl.h>
#include <linux/openat2.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "convert/common/convert_error.h"
#include "convert/common/display_text.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;

fs::path absolute_normal(const fs::path& p) {
  std::error_code ec;
  fs::path abs = fs::absolute(p, ec);
  if (ec) abs = p;
  return abs.lexically_normal();
}

// `path` relative to `root` when it lies inside it (lexically): "." for the root itself.
bool inside(const fs::path& path, const fs::path& root, fs::path& rel) {
  fs::path r = path.lexically_relative(root);
  if (r.empty()) return false;
  auto first = r.begin();
  if (first != r.end() && *first == "..") return false;
  rel = r;
  return true;
}

}  // namespace


PathAccess::PathAccess(std::vector<fs::path> roots, std::string key, std::string source, fs::path base)
    : roots_(std::move(roots)), key_(std::move(key)), source_(std::move(source)), base_(std::move(base)) {}

fs::path PathAccess::resolve(const fs::path& path) const {
  if (path.is_absolute() || base_.empty()) return path.lexically_normal();
  return (base_ / path).lexically_normal();
}

std::string PathAccess::prefix(const fs::path& path) const {
  std::string p;
  if (!source_.empty()) p += display_path(source_) + ": ";
  if (!key_.empty()) p += "key '" + key_ + "': ";
  return p + display_path(path) + ": ";
}

void PathAccess::fail(const fs::path& path, const std::string& problem) const {
  throw ConvertError(prefix(path) + problem);
}

UniqueFd PathAccess::open(const fs::path& given, int flags) const {
  const fs::path path = given.lexically_normal();
  if (path.empty()) fail(given, "empty path");
  flags |= O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK;
  int fd = -1;
  if (roots_.empty()) {
    fd = ::open(path.c_str(), flags);
  } else {
    const fs::path abs = absolute_normal(path);
    const fs::path* root = nullptr;
    fs::path rel;
    for (const fs::path& r : roots_)
      if (inside(abs, r, rel)) {
        root = &r;
        break;
      }
    if (!root) {
      fail(given, "outside the spool (a job may name files only there and in [spool] allow_paths)");
    }
    UniqueFd dir(::open(root->c_str(), O_PATH | O_DIRECTORY | O_CLOEXEC));
    if (dir.get() < 0) fail(given, std::string("cannot open the folder it must be in: ") + std::strerror(errno));
    struct open_how how {};
    how.flags = static_cast<uint64_t>(flags);
    how.resolve = RESOLVE_BENEATH | RESOLVE_NO_SYMLINKS | RESOLVE_NO_MAGICLINKS;
    fd = static_cast<int>(::syscall(SYS_openat2, dir.get(), rel.c_str(), &how, sizeof how));
    if (fd < 0 && errno == ELOOP) fail(given, "goes through a symbolic link, which a job may not use");
    if (fd < 0 && errno == EXDEV) fail(given, "leads outside the spool");
    if (fd < 0 && errno == ENOSYS) fail(given, "cannot be opened safely: the kernel has no openat2 (Linux 5.6 or later)");
  }
  if (fd < 0) {
    const int err = errno;
    if (err == ENOENT) fail(given, "no such file");
    if (err == ENOTDIR) fail(given, (flags & O_DIRECTORY) ? "not a folder" : "a part of the path is not a folder");
    if (err == EACCES || err == EPERM) fail(given, "permission denied");
    fail(given, std::string("cannot open: ") + std::strerror(err));
  }
  return UniqueFd(fd);
}

UniqueFd PathAccess::open_file(const fs::path& path) const {
  UniqueFd fd = open(path, 0);
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0) fail(path, std::string("cannot stat: ") + std::strerror(errno));
  if (S_ISDIR(st.st_mode)) fail(path, "is a folder, not a file");
  if (!S_ISREG(st.st_mode)) fail(path, "not a regular file");
  // Regular files never block; clear O_NONBLOCK for ordinary reads.
  ::fcntl(fd.get(), F_SETFL, ::fcntl(fd.get(), F_GETFL) & ~O_NONBLOCK);
  return fd;
}

UniqueFd PathAccess::open_dir(const fs::path& path) const { return open(path, O_DIRECTORY); }

std::vector<unsigned char> PathAccess::read_file(const fs::path& path, uint64_t max_bytes) const {
  UniqueFd fd = open_file(path);
  struct stat st {};
  ::fstat(fd.get(), &st);
  const auto size = static_cast<uint64_t>(st.st_size);
  if (size > max_bytes) {
    fail(path, "file is " + std::to_string(size) + " bytes, over the limit of " + std::to_string(max_bytes) +
                   " bytes");
  }
  std::vector<unsigned char> data;
  data.reserve(static_cast<size_t>(size));
  unsigned char chunk[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd.get(), chunk, sizeof chunk);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail(path, std::string("read error: ") + std::strerror(errno));
    if (n == 0) break;
    data.insert(data.end(), chunk, chunk + n);
    if (data.size() > max_bytes) {
      fail(path, "file grew over the limit of " + std::to_string(max_bytes) + " bytes while being read");
    }
  }
  return data;
}

std::string PathAccess::read_text(const fs::path& path, uint64_t max_bytes) const {
  std::vector<unsigned char> data = read_file(path, max_bytes);
  return std::string(data.begin(), data.end());
}

std::vector<std::string> PathAccess::list_files(const fs::path& dir_path) const {
  UniqueFd fd = open_dir(dir_path);
  const int listing = ::dup(fd.get());
  DIR* dir = listing >= 0 ? ::fdopendir(listing) : nullptr;
  if (!dir) {
    if (listing >= 0) ::close(listing);
    fail(dir_path, std::string("cannot list the folder: ") + std::strerror(errno));
  }
  std::vector<std::string> names;
  errno = 0;
  while (dirent* e = ::readdir(dir)) {
    const std::string name = e->d_name;
    if (name == "." || name == "..") continue;
    struct stat st {};
    // Confined, a symlink is never a file of the folder; unconfined, it is what it points to.
    const int follow = roots_.empty() ? 0 : AT_SYMLINK_NOFOLLOW;
    if (::fstatat(fd.get(), e->d_name, &st, follow) == 0 && S_ISREG(st.st_mode))
      names.push_back(name);
  }
  ::closedir(dir);
  std::sort(names.begin(), names.end());
  return names;
}

bool PathAccess::is_file(const fs::path& path) const {
  try {
    open_file(path);
    return true;
  } catch (const ConvertError&) {
    return false;
  }
}

bool PathAccess::is_dir(const fs::path& path) const {
  try {
    open_dir(path);
    return true;
  } catch (const ConvertError&) {
    return false;
  }
}

JobPaths::JobPaths(std::vector<fs::path> roots) {
  for (const fs::path& r : roots) roots_.push_back(absolute_normal(r));
}

void JobPaths::mark_from_job(const std::string& key, const std::string& source, const fs::path& base) {
  job_keys_[key] = Origin{source, base};
}

std::string JobPaths::source_of(const std::string& key) const {
  auto it = job_keys_.find(key);
  return it == job_keys_.end() ? std::string() : it->second.source;
}

PathAccess JobPaths::access(const std::string& key, const fs::path& default_base) const {
  auto it = job_keys_.find(key);
  if (it == job_keys_.end()) return PathAccess({}, key, "", default_base);
  return PathAccess(roots_, key, it->second.source, it->second.base.empty() ? default_base : it->second.base);
}

PathAccess JobPaths::companion(const std::string& what) const { return PathAccess(roots_, "", what, {}); }

}  // namespace atelier
