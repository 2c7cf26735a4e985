#include "tools/emu/pty_link.h"

#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <stdexcept>
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
  open_pty();
  if (::symlink(slave_name_.c_str(), link_.c_str()) != 0) {
    const auto e = sys_error(link_ + ": cannot create symlink to " + slave_name_);
    ::close(master_);
    master_ = -1;
    throw e;
  }
}

PtyLink::~PtyLink() { close(); }

void PtyLink::open_pty() {
  int master = -1, slave = -1;
  char name[256] = {};
  if (::openpty(&master, &slave, name, nullptr, nullptr) != 0) throw sys_error("openpty");
  try {
    termios tio {};
    if (::tcgetattr(slave, &tio) != 0) throw sys_error(std::string(name) + ": tcgetattr");
    ::cfmakeraw(&tio);
    ::cfsetspeed(&tio, B115200);
    if (::tcsetattr(slave, TCSANOW, &tio) != 0) throw sys_error(std::string(name) + ": tcsetattr");
    const int flags = ::fcntl(master, F_GETFL);
    if (flags < 0 || ::fcntl(master, F_SETFL, flags | O_NONBLOCK) != 0)
      throw sys_error(std::string(name) + ": cannot make the pty master non-blocking");
    ::fcntl(master, F_SETFD, FD_CLOEXEC);
  } catch (...) {
    ::close(master);
    ::close(slave);
    throw;
  }
  // The settings stay with the pty; the slave is the host's to open. From now until a host
  // opens it, the master reports a hang-up.
  ::close(slave);
  master_ = master;
  slave_name_ = name;
}

int PtyLink::open_slave() const {
  const int fd = ::ioctl(master_, TIOCGPTPEER, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd >= 0 || errno != EINVAL) return fd;
  return ::open(slave_name_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);  // kernels before 4.13
}

bool PtyLink::host_connected() const {
  if (master_ < 0) return false;
  pollfd p{master_, 0, 0};
  return ::poll(&p, 1, 0) >= 0 && !(p.revents & POLLHUP);
}

void PtyLink::after_hangup() {
  if (master_ < 0) return;
  const int fd = open_slave();
  if (fd >= 0) {
    ::ioctl(fd, TIOCNXCL);
    ::tcflush(fd, TCIFLUSH);
    ::close(fd);
    return;
  }
  if (errno != EBUSY) return;  // nothing we can clear; the next host finds the pty as it is
  // A killed host's exclusive lock, and we may not open past it: a fresh pty at the same path,
  // swapped in atomically, so a host finds either the old link or the new one, never none.
  const int old_master = master_;
  const std::string old_name = slave_name_;
  open_pty();
  const std::string tmp = link_ + ".replug";
  ::unlink(tmp.c_str());
  if (::symlink(slave_name_.c_str(), tmp.c_str()) != 0 || ::rename(tmp.c_str(), link_.c_str()) != 0) {
    const auto e = sys_error(link_ + ": cannot point the link at a fresh pty " + slave_name_);
    ::close(master_);
    master_ = old_master;
    slave_name_ = old_name;
    throw e;
  }
  ::close(old_master);
}

bool PtyLink::drain(int max_ms) {
  // Bytes written to the master reach the slave's queue asynchronously (the kernel's flip
  // buffer), so an empty queue right after a write proves nothing: let them land first.
  constexpr int kSettleMs = 50;
  std::this_thread::sleep_for(std::chrono::milliseconds(kSettleMs));
  if (master_ < 0) return true;
  const int slave = open_slave();
  if (slave < 0) return true;  // held exclusively: the settle time is all we can give
  bool drained = false;
  for (int waited = kSettleMs;; waited += 2) {
    int unread = 0;
    if (::ioctl(slave, TIOCINQ, &unread) != 0 || unread == 0) {
      drained = true;
      break;
    }
    if (waited >= max_ms) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ::close(slave);
  return drained;
}

void PtyLink::close() {
  if (master_ < 0) return;
  char target[256] = {};
  const ssize_t n = ::readlink(link_.c_str(), target, sizeof target - 1);
  if (n > 0 && slave_name_ == std::string(target, static_cast<size_t>(n))) ::unlink(link_.c_str());
  ::close(master_);
  master_ = -1;
}

}  // namespace atelier::emu
