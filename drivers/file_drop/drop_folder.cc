#include "drivers/file_drop/drop_folder.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <unistd.h>

namespace atelier {
namespace {

[[noreturn]] void fail(const std::filesystem::path& dir, const std::string& doing, int err) {
  throw DropError(dir.string() + ": " + std::strerror(err) + " " + doing, err);
}

}  // namespace

bool PosixDropFolder::present() const {
  std::error_code ec;
  return std::filesystem::is_directory(dir_, ec);
}

void PosixDropFolder::write_atomically(const std::string& name, std::string_view bytes) {
  const std::string doing = "writing " + name;
  if (!present()) fail(dir_, doing, ENOENT);
  // Hidden, so a machine listing the stick never offers the half-written file.
  const std::filesystem::path tmp = dir_ / ("." + name + ".part");
  const std::filesystem::path final_path = dir_ / name;
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail(dir_, doing, errno);
  auto give_up = [&](int err) {
    ::close(fd);
    ::unlink(tmp.c_str());
    fail(dir_, doing, err);
  };
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      give_up(errno);
    }
    done += static_cast<size_t>(n);
  }
  // A full FAT stick may only say so when the data is flushed.
  if (::fsync(fd) != 0) give_up(errno);
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    fail(dir_, doing, err);
  }
  // Never replace a file already there (another store's job of the same id, say).
  int moved = ::renameat2(AT_FDCWD, tmp.c_str(), AT_FDCWD, final_path.c_str(), RENAME_NOREPLACE);
  if (moved != 0 && errno == EINVAL) {  // a file system without the flag: check, then rename
    std::error_code ec;
    if (std::filesystem::exists(final_path, ec)) errno = EEXIST;
    else moved = ::rename(tmp.c_str(), final_path.c_str());
  }
  if (moved != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    fail(dir_, doing, err);
  }
  const int dfd = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);  // the rename reaches the stick before we say "completed"
    ::close(dfd);
  }
}

void PosixDropFolder::remove(const std::string& name) noexcept {
  std::error_code ec;
  std::filesystem::remove(dir_ / name, ec);
}

}  // namespace atelier
