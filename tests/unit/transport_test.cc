// Transports: the in-memory pair and the serial port on a real pseudo-terminal.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <pty.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <future>
#include <string>

#include "drivers/memory_transport.h"
#include "drivers/serial_transport.h"

namespace atelier {
namespace {

using namespace std::chrono_literals;

std::string read_all(Transport& t, size_t want) {
  std::string out;
  uint8_t buf[64];
  while (out.size() < want) {
    const size_t n = t.read(buf, sizeof buf, 2000ms);
    if (n == 0) break;
    out.append(reinterpret_cast<char*>(buf), n);
  }
  return out;
}

void write_str(Transport& t, const std::string& s) {
  t.write(reinterpret_cast<const uint8_t*>(s.data()), s.size());
}

TEST(TransportMemory, BytesFlowBothWaysAndTimeoutReturnsZero) {
  auto [a, b] = make_memory_pair();
  write_str(*a, "hello");
  write_str(*b, "back");
  EXPECT_EQ(read_all(*b, 5), "hello");
  EXPECT_EQ(read_all(*a, 4), "back");
  uint8_t buf[4];
  EXPECT_EQ(a->read(buf, sizeof buf, 10ms), 0u);
}

TEST(TransportMemory, FlushInputDiscardsUnreadBytes) {
  auto [a, b] = make_memory_pair();
  write_str(*a, "noise");
  b->flush_input();
  write_str(*a, "ok");
  EXPECT_EQ(read_all(*b, 2), "ok");
}

TEST(TransportMemory, DisconnectMakesBothEndsThrowLinkLost) {
  auto [a, b] = make_memory_pair();
  b->disconnect();
  uint8_t buf[4];
  EXPECT_THROW(a->read(buf, sizeof buf, 10ms), LinkLost);
  EXPECT_THROW(write_str(*a, "x"), LinkLost);
  EXPECT_THROW(b->read(buf, sizeof buf, 10ms), LinkLost);
}

TEST(TransportMemory, DisconnectWakesABlockedReader) {
  auto [a, b] = make_memory_pair();
  auto reader = std::async(std::launch::async, [&a = *a] {
    uint8_t buf[4];
    try {
      a.read(buf, sizeof buf, 60000ms);
    } catch (const LinkLost&) {
      return true;
    }
    return false;
  });
  b->disconnect();
  ASSERT_EQ(reader.wait_for(10s), std::future_status::ready) << "reader still blocked";
  EXPECT_TRUE(reader.get());
}

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

std::string read_master(int fd, size_t want) {
  std::string out;
  char buf[64];
  for (int tries = 0; out.size() < want && tries < 200; ++tries) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n > 0) out.append(buf, static_cast<size_t>(n));
    else usleep(10000);
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
  auto reader = std::async(std::launch::async, [&] {
    uint8_t buf[4];
    try {
      port->read(buf, sizeof buf, 60000ms);
    } catch (const LinkLost&) {
      return true;
    }
    return false;
  });
  std::this_thread::sleep_for(50ms);  // let the reader block (the test holds either way)
  port->close();
  ASSERT_EQ(reader.wait_for(10s), std::future_status::ready) << "reader still blocked";
  EXPECT_TRUE(reader.get());
}

}  // namespace
}  // namespace atelier
