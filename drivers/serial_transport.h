// A serial port (USB CDC-ACM Arduino, FTDI, or a pseudo-terminal) as a Transport:
// 115200 baud, 8N1, no flow control, raw, opened with O_NOCTTY and made exclusive (TIOCEXCL,
// so a second non-root opener gets EBUSY), with HUPCL set: the port's last close - ours, or
// the kernel's when the daemon is killed - drops DTR, and the next open raises it, which resets
// an Arduino (on a pseudo-terminal the emulator at the master sees the hang-up).
//
// Opening: libserialport opens and configures ports it can describe (real devices found in
// sysfs). libserialport 0.1.1 refuses pseudo-terminals and symlinks outside /dev (it looks
// each name up in /sys/class/tty), so those are opened with open(2) + termios instead; both
// paths end with the same fd-based I/O.
// Reading waits with poll(2) on the port and an eventfd, so close() from another thread wakes
// a blocked read at once. Link loss (USB unplugged, pty master closed: EIO, POLLHUP, EOF)
// throws LinkLost("<path>: ...").
//
// Threading: one reader and one writer thread at once; close() from any thread.
#pragma once

#include <atomic>
#include <memory>
#include <string>

#include "drivers/transport.h"

struct sp_port;

namespace atelier {

class SerialTransport : public Transport {
 public:
  // Opens and configures `path`. Throws LinkLost naming the path when it does not exist or
  // vanished, std::runtime_error naming the path when it is busy or not a serial port.
  static std::unique_ptr<SerialTransport> open(const std::string& path);
  ~SerialTransport() override;
  SerialTransport(const SerialTransport&) = delete;
  SerialTransport& operator=(const SerialTransport&) = delete;

  void write(const uint8_t* data, size_t size) override;
  size_t read(uint8_t* data, size_t max, std::chrono::milliseconds timeout) override;
  void flush_input() override;
  // TIOCMBIC/TIOCMBIS on DTR and RTS; on a port without modem lines (a pty) a hang-up: the
  // port is closed for `low` and reopened (up to 2 s more while it is busy or missing) with
  // the same settings. Call it from the thread that reads and writes, never during a read.
  void pulse_dtr(std::chrono::milliseconds low) override;
  // Wakes a blocked read (which then throws LinkLost "closed") and drops the exclusive lock;
  // the descriptor is released by the destructor.
  void close() override;

  const std::string& path() const { return path_; }
  int fd() const { return fd_; }  // for tests (e.g. checking TIOCEXCL)

 private:
  SerialTransport(std::string path, int fd, sp_port* port, int wake_fd);
  [[noreturn]] void lost(const std::string& why) const;

  std::string path_;
  const int fd_;
  sp_port* port_;     // owned; null when opened without libserialport (pty)
  int wake_fd_;       // eventfd signalled by close()
  std::atomic<bool> closed_{false};
};

}  // namespace atelier
