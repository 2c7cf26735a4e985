// The serial transport (drivers/serial_transport.h) on a real pseudo-terminal, whose own
// timeouts are real time: the only real waits in the unit tests besides real_clock()'s.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <pty.h>
#include <termios.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <future>
#include <string>
#include <thread>

#include "drivers/serial_transport.h"
#include "tests/support/thread_state.h"
#include "tests/unit/drivers/transport_fixture.h"

namespace atelier {
namespace {

using namespace std::chrono_literals;

using test::read_all;
using test::write_str;

// A pseudo-terminal: the test holds the master (the "device"), the transport opens the slave.
struct Pty {
  int master = -1;
  std::string slave;
  Pty() {
    int s = -1;
    char name[128];
    if (openpty(&master, &s, name, nullptr, nullptr) != 0) throw std::runtime_error("openpty failed");
    slave = name;
    ::close(s);  // the transport opens its own descriptor
  }
  ~Pty() {
    if (master >= 0) ::close(master);
  }
  void close_master() {
    ::close(master);
    master = -1;
  }
};

// What the transport wrote, as the device sees it: reads until `want` bytes came, or nothing
// comes for 2 s (the pty's own real-time wait; it ends as soon as the bytes are there).
std::string read_master(int fd, size_t want) {
  std::string out;
  char buf[64];
  while (out.size() < want) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 2000) <= 0) break;
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n <= 0) break;
    out.append(buf, static_cast<size_t>(n));
  }
  return out;
}

TEST(TransportSerial, BytesBothWaysOnAPty) {
  Pty pty;
  auto port = SerialTransport::open(pty.slave);
  const uint8_t binary[] = {0xC0, 0x03, 0x00, 0xDB, 0xC0};  // raw mode: no byte is special
  port->write(binary, sizeof binary);
  fcntl(pty.master, F_SETFL, fcntl(pty.master, F_GETFL) | O_NONBLOCK);
  EXPECT_EQ(read_master(pty.master, 5), std::string(reinterpret_cast<const char*>(binary), 5));
  ASSERT_EQ(::write(pty.master, "\x11\x13\r\n\x03", 5), 5);  // XON, XOFF, CR, LF, ^C
  EXPECT_EQ(read_all(*port, 5), std::string("\x11\x13\r\n\x03", 5));
}

TEST(TransportSerial, ReadTimeoutReturnsZero) {
  Pty pty;
  auto port = SerialTransport::open(pty.slave);
  uint8_t buf[8];
  EXPECT_EQ(port->read(buf, sizeof buf, 30ms), 0u);
}

TEST(TransportSerial, MasterClosedIsLinkLostNamingThePath) {
  Pty pty;
  auto port = SerialTransport::open(pty.slave);
  pty.close_master();
  uint8_t buf[8];
  try {
    port->read(buf, sizeof buf, 5000ms);
    FAIL() << "expected LinkLost";
  } catch (const LinkLost& e) {
    EXPECT_NE(std::string(e.what()).find(pty.slave), std::string::npos) << e.what();
  }
  EXPECT_THROW(port->write(buf, 1), LinkLost);
}

TEST(TransportSerial, OpensThroughASymlinkAndHoldsThePortExclusively) {
  Pty pty;
  const auto link = std::filesystem::temp_directory_path() / ("atelier-transport-" + std::to_string(getpid()));
  std::filesystem::remove(link);
  std::filesystem::create_symlink(pty.slave, link);
  auto port = SerialTransport::open(link.string());
  int exclusive = 0;
  ASSERT_EQ(ioctl(port->fd(), TIOCGEXCL, &exclusive), 0);
  EXPECT_EQ(exclusive, 1);
  ASSERT_EQ(::write(pty.master, "ab", 2), 2);
  EXPECT_EQ(read_all(*port, 2), "ab");
  std::filesystem::remove(link);
}

TEST(TransportSerial, MissingPortAndNonTtyNameThePath) {
  try {
    SerialTransport::open("/dev/atelier-no-such-port");
    FAIL() << "expected LinkLost";
  } catch (const LinkLost& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/atelier-no-such-port"), std::string::npos) << e.what();
  }
  const auto file = std::filesystem::temp_directory_path() / ("atelier-not-a-tty-" + std::to_string(getpid()));
  std::ofstream(file) << "x";
  try {
    SerialTransport::open(file.string());
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not a serial port"), std::string::npos) << e.what();
  }
  std::filesystem::remove(file);
}

TEST(TransportSerial, CloseWakesABlockedRead) {
  Pty pty;
  auto port = SerialTransport::open(pty.slave);
  std::promise<pid_t> reader_tid;
  auto reader = std::async(std::launch::async, [&] {
    reader_tid.set_value(test::this_thread_id());
    uint8_t buf[4];
    try {
      port->read(buf, sizeof buf, 60000ms);
    } catch (const LinkLost&) {
      return true;
    }
    return false;
  });
  // The reader is blocked in the poll(2) of its read (glibc may use ppoll for it).
#ifdef SYS_poll
  test::wait_until_in_syscall(reader_tid.get_future().get(), {SYS_poll, SYS_ppoll});
#else
  test::wait_until_in_syscall(reader_tid.get_future().get(), {SYS_ppoll});
#endif
  port->close();
  // The pty transport's own wait is real time: a close that did not wake it is found here.
  ASSERT_EQ(reader.wait_for(10s), std::future_status::ready) << "reader still blocked";
  EXPECT_TRUE(reader.get());
}

TEST(TransportSerial, OpensWithHupclSoItsCloseDropsDtr) {
  // A port left without HUPCL (`stty -hupcl`, or a program that cleared it) would keep DTR up
  // after our close - or after the kernel's, when the daemon is killed - and the board running.
  Pty pty;
  {
    const int fd = ::open(pty.slave.c_str(), O_RDWR | O_NOCTTY);
    ASSERT_GE(fd, 0);
    termios t{};
    ASSERT_EQ(::tcgetattr(fd, &t), 0);
    t.c_cflag &= ~static_cast<tcflag_t>(HUPCL);
    ASSERT_EQ(::tcsetattr(fd, TCSANOW, &t), 0);
    ::close(fd);
  }
  auto port = SerialTransport::open(pty.slave);
  termios t{};
  ASSERT_EQ(::tcgetattr(port->fd(), &t), 0);
  EXPECT_TRUE(t.c_cflag & HUPCL) << "HUPCL not set: closing the port would not drop DTR";
}

// Whether the pty's master sees its slave hung up (no descriptor on it open) now.
bool hung_up(int master) {
  pollfd p{master, 0, 0};
  return ::poll(&p, 1, 0) == 1 && (p.revents & POLLHUP);
}

TEST(TransportSerial, PulseDtrOnAPtyHangsUpForTheWholePulseAndComesBack) {
  Pty pty;
  auto port = SerialTransport::open(pty.slave);
  ASSERT_FALSE(hung_up(pty.master));
  // The pulse blocks this thread for its length; the device watches the line meanwhile.
  auto pulse = std::async(std::launch::async, [&] { port->pulse_dtr(300ms); });
  bool saw_hangup = false;
  for (int i = 0; i < 200 && !saw_hangup; ++i) {  // up to 2 s of 10 ms looks
    saw_hangup = hung_up(pty.master);
    if (!saw_hangup) std::this_thread::sleep_for(10ms);
  }
  pulse.get();
  EXPECT_TRUE(saw_hangup) << "the device never saw DTR drop";
  EXPECT_FALSE(hung_up(pty.master)) << "the port did not come back after the pulse";
  // The same transport works on: both ways.
  ASSERT_EQ(::write(pty.master, "hello", 5), 5);
  EXPECT_EQ(read_all(*port, 5), "hello");
  write_str(*port, "ok");
  EXPECT_EQ(read_master(pty.master, 2), "ok");
  int held = 0;
  termios t{};
  ASSERT_EQ(::tcgetattr(port->fd(), &t), 0);
  EXPECT_TRUE(t.c_cflag & HUPCL);
  EXPECT_EQ(::ioctl(port->fd(), TIOCGEXCL, &held), 0);
  EXPECT_EQ(held, 1) << "the reopened port is not held exclusively";
}

}  // namespace
}  // namespace atelier
