#include "tools/emu/pty_link.h"

#include <fcntl.h>
#include <pty.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <chrono>
#include <thread>

#include "base/error.h"

namespace atelier::emu {
namespace {

std::runtime_error sys_error(const std::string& what) {
  return std::runtime_error(what + ": " + std::strerror(errno));
}

}  // namespace

PtyLink::PtyLink(const std::string& link_path) : link_(link_path) {
  struct stat st {};
  if (::lstat(link_.c_str(), &st) == 0) {
    if (!S_ISLNK(st.st_mode))
      throw BadInput(link_ + ": exists and is not a symlink; refusing to replace it");
    if (::unlink(link_.c_str()) != 0) throw sys_error(link_ + ": cannot remove the old symlink");
  }
  char name[256] = {};
  if (::openpty(&master_, &slave_, name, nullptr, nullptr) != 0) throw sys_error("openpty");
  slave_name_ = name;
  try {
    termios tio {};
    if (::tcgetattr(slave_, &tio) != 0) throw sys_error(slave_name_ + ": tcgetattr");
    ::cfmakeraw(&tio);
    ::cfsetspeed(&tio, B115200);
    if (::tcsetattr(slave_, TCSANOW, &tio) != 0) throw sys_error(slave_name_ + ": tcsetattr");
    const int flags = ::fcntl(master_, F_GETFL);
    if (flags < 0 || ::fcntl(master_, F_SETFL, flags | O_NONBLOCK) != 0)
      throw sys_error(slave_name_ + ": cannot make the pty master non-blocking");
    ::fcntl(master_, F_SETFD, FD_CLOEXEC);
    ::fcntl(slave_, F_SETFD, FD_CLOEXEC);
    if (::symlink(slave_name_.c_str(), link_.c_str()) != 0)
      throw sys_error(link_ + ": cannot create symlink to " + slave_name_);
  } catch (...) {
    ::close(master_);
    ::close(slave_);
    throw;
  }
}

PtyLink::~PtyLink() { close(); }

bool PtyLink::drain(int max_ms) {
  // Bytes written to the master reach the slave's queue asynchronously (the kernel's flip
  // buffer), so an empty queue right after a write proves nothing: let them land first.
  constexpr int kSettleMs = 50;
  std::this_thread::sleep_for(std::chrono::milliseconds(kSettleMs));
  for (int waited = kSettleMs; master_ >= 0; waited += 2) {
    int unread = 0;
    if (::ioctl(slave_, TIOCINQ, &unread) != 0 || unread == 0) return true;
    if (waited >= max_ms) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

void PtyLink::close() {
  if (master_ < 0) return;
  char target[256] = {};
  const ssize_t n = ::readlink(link_.c_str(), target, sizeof target - 1);
  if (n > 0 && slave_name_ == std::string(target, static_cast<size_t>(n))) ::unlink(link_.c_str());
  ::close(master_);
  ::close(slave_);
  master_ = slave_ = -1;
}

}  // namespace atelier::emu
