// The emulators' pseudo-terminal (tools/emu/pty_link.h): the host's open and close are the
// board's DTR line - the link keeps no slave descriptor of its own that would hide the close -
// and a host that went away leaves nothing behind for the next one.
#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tools/emu/pty_link.h"

namespace atelier::emu {
namespace {

namespace fs = std::filesystem;

fs::path temp_link(const std::string& name) {
  return fs::temp_directory_path() / ("pty_link_" + name + "_" + std::to_string(::getpid()));
}

// Bytes waiting for the host on `fd`, read without blocking (raw mode: no line discipline).
std::string available(int fd) {
  std::string out;
  char buf[64];
  for (ssize_t n; (n = ::read(fd, buf, sizeof buf)) > 0;) out.append(buf, static_cast<size_t>(n));
  return out;
}

TEST(EmuPtyLink, TheHostsOpenAndCloseAreSeenAndAHostThatWentLeavesNothingBehind) {
  const fs::path path = temp_link("dtr");
  PtyLink link(path.string());
  EXPECT_FALSE(link.host_connected()) << "nobody has opened the port yet";

  int host = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
  ASSERT_GE(host, 0);
  EXPECT_TRUE(link.host_connected());
  ASSERT_EQ(::ioctl(host, TIOCEXCL), 0);
  ASSERT_EQ(::write(link.master_fd(), "unread", 6), 6);  // the host dies before reading it
  ::close(host);
  EXPECT_FALSE(link.host_connected()) << "the close went unseen";

  link.after_hangup();
  host = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
  ASSERT_GE(host, 0);
  EXPECT_TRUE(link.host_connected());
  int exclusive = 1;
  ASSERT_EQ(::ioctl(host, TIOCGEXCL, &exclusive), 0);
  EXPECT_EQ(exclusive, 0) << "the dead host's exclusive lock would keep the next one out";
  pollfd p{host, POLLIN, 0};
  ::poll(&p, 1, 50);  // bytes still in flight would land by now
  EXPECT_EQ(available(host), "") << "the next host reads what the last one left";
  ASSERT_EQ(::write(link.master_fd(), "fresh", 5), 5);
  p = {host, POLLIN, 0};
  ASSERT_EQ(::poll(&p, 1, 2000), 1);
  EXPECT_EQ(available(host), "fresh");
  ::close(host);
}

TEST(EmuPtyLink, CloseRemovesTheLink) {
  const fs::path path = temp_link("close");
  {
    PtyLink link(path.string());
    EXPECT_TRUE(fs::is_symlink(path));
  }
  EXPECT_FALSE(fs::exists(fs::symlink_status(path)));
}

}  // namespace
}  // namespace atelier::emu
