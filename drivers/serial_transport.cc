#include "drivers/serial_transport.h"

#include <fcntl.h>
#include <libserialport.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "base/error.h"

namespace atelier {
namespace {

std::string errno_text(int e) { return std::strerror(e); }

// Opens and configures a port libserialport knows; returns null (and the fd untouched) when
// libserialport cannot describe the port (pseudo-terminals), throws when the port is busy.
sp_port* open_with_libserialport(const std::string& path, const std::string& real, int& fd) {
  sp_port* port = nullptr;
  if (sp_get_port_by_name(real.c_str(), &port) != SP_OK) return nullptr;
  if (sp_open(port, SP_MODE_READ_WRITE) != SP_OK) {
    const int e = errno;
    const std::string why = sp_last_error_message();
    sp_free_port(port);
    if (e == EBUSY) throw DeviceError(path + ": serial port is busy (opened by another program)");
    if (e == ENOENT || e == ENODEV || e == ENXIO) throw LinkLost(path + ": " + errno_text(e));
    throw DeviceError(path + ": cannot open serial port: " + why);
  }
  // Set each parameter on its own: sp_set_flowcontrol() would also drive RTS/DTR.
  if (sp_set_baudrate(port, 115200) != SP_OK || sp_set_bits(port, 8) != SP_OK ||
      sp_set_parity(port, SP_PARITY_NONE) != SP_OK || sp_set_stopbits(port, 1) != SP_OK ||
      sp_set_xon_xoff(port, SP_XONXOFF_DISABLED) != SP_OK || sp_set_cts(port, SP_CTS_IGNORE) != SP_OK ||
      sp_set_dsr(port, SP_DSR_IGNORE) != SP_OK) {
    const std::string why = sp_last_error_message();
    sp_close(port);
    sp_free_port(port);
    throw DeviceError(path + ": cannot configure serial port: " + why);
  }
  sp_get_port_handle(port, &fd);
  return port;
}

int open_with_termios(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    const int e = errno;
    if (e == EBUSY) throw DeviceError(path + ": serial port is busy (opened by another program)");
    if (e == ENOENT || e == ENODEV || e == ENXIO || e == EIO) throw LinkLost(path + ": " + errno_text(e));
    throw DeviceError(path + ": cannot open serial port: " + errno_text(e));
  }
  termios t{};
  if (tcgetattr(fd, &t) != 0) {
    const int e = errno;
    ::close(fd);
    throw DeviceError(path + ": not a serial port: " + errno_text(e));
  }
  cfmakeraw(&t);
  cfsetispeed(&t, B115200);
  cfsetospeed(&t, B115200);
  t.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | PARENB | CRTSCTS | CSIZE);
  t.c_cflag |= CS8 | CLOCAL | CREAD;
  t.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  if (tcsetattr(fd, TCSANOW, &t) != 0) {
    const int e = errno;
    ::close(fd);
    throw DeviceError(path + ": cannot configure serial port: " + errno_text(e));
  }
  return fd;
}

// Exclusive use, non-blocking, close-on-exec and HUPCL on an open port; returns "" or what
// failed (with errno's text).
std::string finish_setup(int fd) {
  // Exclusive use: a second opener (other than root) gets EBUSY while we hold the port.
  if (ioctl(fd, TIOCEXCL) != 0) return "cannot lock serial port: " + errno_text(errno);
  const int flags = fcntl(fd, F_GETFL);
  fcntl(fd, F_SETFL, flags | O_NONBLOCK);
  // libserialport opens without O_CLOEXEC: converter children must not inherit the machine.
  fcntl(fd, F_SETFD, fcntl(fd, F_GETFD) | FD_CLOEXEC);
  // Hang up on close: the last close (also the kernel's, when the daemon is killed) drops DTR,
  // so an Arduino wired to reset on it does, and the next open's DTR edge resets any Uno. A
  // port left with -hupcl (`stty -hupcl`, or another program before us) would keep DTR up
  // after the close, and the next open would not reset the board.
  termios t{};
  if (tcgetattr(fd, &t) != 0) return "not a serial port: " + errno_text(errno);
  t.c_cflag |= HUPCL;
  if (tcsetattr(fd, TCSANOW, &t) != 0) return "cannot set HUPCL: " + errno_text(errno);
  return "";
}

}  // namespace

std::unique_ptr<SerialTransport> SerialTransport::open(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw LinkLost(path + ": " + errno_text(errno));
  char resolved[PATH_MAX];
  const std::string real = ::realpath(path.c_str(), resolved) ? resolved : path;

  int fd = -1;
  sp_port* port = open_with_libserialport(path, real, fd);
  if (!port) fd = open_with_termios(path);
  auto release = [&] {
    if (port) {
      sp_close(port);
      sp_free_port(port);
    } else {
      ::close(fd);
    }
  };
  if (const std::string problem = finish_setup(fd); !problem.empty()) {
    release();
    throw DeviceError(path + ": " + problem);
  }
  const int wake = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (wake < 0) {
    const int e = errno;
    release();
    throw DeviceError(path + ": eventfd: " + errno_text(e));
  }
  return std::unique_ptr<SerialTransport>(new SerialTransport(path, fd, port, wake));
}

SerialTransport::SerialTransport(std::string path, int fd, sp_port* port, int wake_fd)
    : path_(std::move(path)), fd_(fd), port_(port), wake_fd_(wake_fd) {}

SerialTransport::~SerialTransport() {
  close();
  if (port_) {
    sp_close(port_);
    sp_free_port(port_);
  } else {
    ::close(fd_);
  }
  ::close(wake_fd_);
}

void SerialTransport::lost(const std::string& why) const { throw LinkLost(path_ + ": " + why); }

void SerialTransport::write(const uint8_t* data, size_t size) {
  size_t done = 0;
  while (done < size) {
    if (closed_) lost("closed");
    const ssize_t n = ::write(fd_, data + done, size - done);
    if (n > 0) {
      done += static_cast<size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno == EAGAIN) {
      pollfd p[2] = {{fd_, POLLOUT, 0}, {wake_fd_, POLLIN, 0}};
      if (poll(p, 2, 1000) < 0 && errno != EINTR) lost(std::string("poll: ") + errno_text(errno));
      if (p[0].revents & (POLLHUP | POLLERR)) lost("device disconnected");
      continue;
    }
    lost(n < 0 ? errno_text(errno) : "write returned 0");
  }
}

size_t SerialTransport::read(uint8_t* data, size_t max, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    if (closed_) lost("closed");
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    pollfd p[2] = {{fd_, POLLIN, 0}, {wake_fd_, POLLIN, 0}};
    const int ready = poll(p, 2, static_cast<int>(std::max<int64_t>(0, left.count())));
    if (ready < 0) {
      if (errno == EINTR) continue;
      lost(std::string("poll: ") + errno_text(errno));
    }
    if (closed_ || (p[1].revents & POLLIN)) lost("closed");
    if (p[0].revents & POLLNVAL) lost("port closed");
    if (p[0].revents & (POLLIN | POLLHUP | POLLERR)) {
      // Read even on HUP: bytes sent just before the peer went away are still delivered.
      const ssize_t n = ::read(fd_, data, max);
      if (n > 0) return static_cast<size_t>(n);
      if (n == 0) lost("device disconnected (end of file)");
      if (errno == EINTR || errno == EAGAIN) {
        if (p[0].revents & (POLLHUP | POLLERR)) lost("device disconnected");
        continue;
      }
      lost(errno == EIO ? std::string("device disconnected (I/O error)") : errno_text(errno));
    }
    if (ready == 0 && std::chrono::steady_clock::now() >= deadline) return 0;
  }
}

void SerialTransport::flush_input() {
  if (closed_) lost("closed");
  tcflush(fd_, TCIFLUSH);
}

void SerialTransport::pulse_dtr(std::chrono::milliseconds low) {
  if (closed_) lost("closed");
  int lines = TIOCM_DTR | TIOCM_RTS;
  if (ioctl(fd_, TIOCMBIC, &lines) == 0) {
    std::this_thread::sleep_for(low);
    if (ioctl(fd_, TIOCMBIS, &lines) != 0) lost("cannot raise DTR again: " + errno_text(errno));
    tcflush(fd_, TCIFLUSH);
    return;
  }
  if (errno != ENOTTY && errno != EINVAL) lost("cannot drop DTR: " + errno_text(errno));
  // No modem lines (a pseudo-terminal): hang up by closing the port, then open it again. The
  // descriptor number stays valid throughout (/dev/null stands in), so nothing ever touches a
  // reused number.
  ioctl(fd_, TIOCNXCL);
  const int null_fd = ::open("/dev/null", O_RDWR | O_CLOEXEC);
  if (null_fd < 0 || ::dup3(null_fd, fd_, O_CLOEXEC) < 0) {
    const int e = errno;
    if (null_fd >= 0) ::close(null_fd);
    lost("cannot hang up: " + errno_text(e));
  }
  ::close(null_fd);
  std::this_thread::sleep_for(low);
  // The port may take a moment to come back (an emulator clearing up after the hang-up).
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  for (;;) {
    if (closed_) lost("closed");
    try {
      const int fresh = open_with_termios(path_);
      const std::string problem = finish_setup(fresh);
      if (!problem.empty()) {
        ::close(fresh);
        lost(problem);
      }
      const int moved = ::dup3(fresh, fd_, O_CLOEXEC);
      const int e = errno;
      ::close(fresh);
      if (moved < 0) lost("cannot reopen after the hang-up: " + errno_text(e));
      tcflush(fd_, TCIFLUSH);
      return;
    } catch (const LinkLost&) {
      if (std::chrono::steady_clock::now() >= give_up) throw;
    } catch (const DeviceError& e) {  // busy
      if (std::chrono::steady_clock::now() >= give_up) lost(std::string("cannot reopen after the hang-up: ") + e.what());
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

void SerialTransport::close() {
  if (closed_.exchange(true)) return;
  const uint64_t one = 1;
  [[maybe_unused]] const ssize_t w = ::write(wake_fd_, &one, sizeof one);
  // Give up exclusivity now so the port can be reopened (e.g. after a replug); the fd itself
  // stays open until destruction so a reader still in poll() never touches a reused number.
  ioctl(fd_, TIOCNXCL);
}

}  // namespace atelier
