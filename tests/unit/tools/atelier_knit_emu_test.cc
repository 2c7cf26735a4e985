// The real atelier-knit-emu program on a pseudo-terminal, driven by hand with the message
// encoders. The program keeps the real clock (its model runs on it), so this test cannot use a
// fake one: it waits only for the program's own events - bytes on the pty, the link going and
// coming back (inotify) - each wait bounded by a guard against hangs. Nothing here sleeps,
// reads the clock or asserts on speed.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/inotify.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <deque>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "drivers/ayab/messages.h"
#include "drivers/ayab/slip.h"

namespace {

namespace ab = atelier::ayab;
namespace fs = std::filesystem;
// Longest wait for the program's next event before the test calls it hung.
constexpr int kHangGuardMs = 10000;

class Emulator {
 public:
  explicit Emulator(std::vector<std::string> args) {
    int out[2];
    EXPECT_EQ(::pipe(out), 0);
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(out[1], STDOUT_FILENO);
      ::close(out[0]);
      ::close(out[1]);
      const std::string bin = ATELIER_BINARY_DIR "/bin/atelier-knit-emu";
      std::vector<char*> argv{const_cast<char*>(bin.c_str())};
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execv(bin.c_str(), argv.data());
      ::_exit(127);
    }
    ::close(out[1]);
    stdout_ = out[0];
  }
  ~Emulator() {
    if (pid_ > 0) stop();
    if (stdout_ >= 0) ::close(stdout_);
  }
  // The first stdout line ("atelier-knit-emu: kh930 on /dev/pts/N linked at PATH").
  std::string ready_line() { return next_line(); }
  // The next stdout line (e.g. "atelier-knit-emu: DTR dropped ..." when a host went away).
  std::string next_line() {
    std::string line;
    char c;
    pollfd p{stdout_, POLLIN, 0};
    while (::poll(&p, 1, kHangGuardMs) > 0 && ::read(stdout_, &c, 1) == 1 && c != '\n') line.push_back(c);
    return line;
  }
  int stop() {
    ::kill(pid_, SIGTERM);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

 private:
  pid_t pid_ = -1;
  int stdout_ = -1;
};

class Port {
 public:
  explicit Port(const std::string& path) : fd_(::open(path.c_str(), O_RDWR | O_NOCTTY)) {
    if (fd_ < 0) return;
    termios tio{};
    ::tcgetattr(fd_, &tio);
    ::cfmakeraw(&tio);
    ::tcsetattr(fd_, TCSANOW, &tio);
  }
  ~Port() {
    if (fd_ >= 0) ::close(fd_);
  }
  bool ok() const { return fd_ >= 0; }
  void send(const ab::Message& m) {
    const ab::Bytes b = ab::slip_encode(ab::encode(m));
    ASSERT_EQ(::write(fd_, b.data(), b.size()), static_cast<ssize_t>(b.size()));
  }
  // Reads messages until one satisfies `want`; nullopt on link loss, or when nothing comes
  // for kHangGuardMs.
  template <class T>
  std::optional<T> wait_for(const std::function<bool(const T&)>& want = [](const T&) { return true; },
                            int guard_ms = kHangGuardMs) {
    for (;;) {
      for (auto& m : pending_) {
        if (auto* t = std::get_if<T>(&m); t && want(*t)) {
          T found = *t;
          pending_.clear();
          return found;
        }
      }
      pending_.clear();
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, guard_ms) <= 0) return std::nullopt;
      uint8_t buf[512];
      const ssize_t n = ::read(fd_, buf, sizeof buf);
      if (n <= 0) return std::nullopt;
      for (const auto& pkt : dec_.feed(buf, static_cast<size_t>(n))) {
        auto d = ab::decode(pkt, 25);
        if (d.message) pending_.push_back(*d.message);
      }
    }
  }

 private:
  int fd_;
  ab::SlipDecoder dec_;
  std::vector<ab::Message> pending_;
};

ab::CnfLine line(uint8_t n, const std::string& needles, bool last = false) {
  ab::CnfLine c;
  c.line = n;
  c.last_line = last;
  c.needles.assign(25, 0);
  for (size_t i = 0; i < needles.size(); ++i) ab::select_needle(c.needles, static_cast<int>(i), needles[i] == '1');
  return c;
}

// Knits `rows` (needles 0..7) from line number `first`; returns false if a reply is missing.
void knit(Port& port, const std::vector<std::string>& rows, uint8_t first) {
  for (size_t i = 0; i < rows.size(); ++i) {
    const auto n = static_cast<uint8_t>(first + i);
    port.send(line(n, rows[i]));
    auto next = port.wait_for<ab::ReqLine>([&](const ab::ReqLine& r) { return r.line == uint8_t(n + 1); });
    ASSERT_TRUE(next) << "no reqLine after line " << int(n);
  }
}

void init_and_start(Port& port) {
  port.send(ab::ReqInfo{});
  auto info = port.wait_for<ab::CnfInfo>();
  ASSERT_TRUE(info);
  EXPECT_EQ(info->api, 6);
  port.send(ab::ReqInit{ab::MachineType::kh930});
  auto init = port.wait_for<ab::CnfInit>();
  ASSERT_TRUE(init);
  ASSERT_EQ(init->error, 0);
  ASSERT_TRUE(port.wait_for<ab::IndState>());
  port.send(ab::ReqStart{0, 7, false, false});
  ASSERT_TRUE(port.wait_for<ab::ReqLine>([](const ab::ReqLine& r) { return r.line == 0; }));
}

std::vector<std::string> read_lines(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

// What happens to the entries of a folder (inotify), so the test sees the link go and come
// back when it does, without polling for it.
class FolderWatch {
 public:
  explicit FolderWatch(const fs::path& dir) : fd_(::inotify_init1(IN_CLOEXEC)) {
    EXPECT_GE(fd_, 0);
    EXPECT_GE(::inotify_add_watch(fd_, dir.c_str(), IN_CREATE | IN_DELETE | IN_MOVED_TO | IN_MOVED_FROM), 0);
  }
  ~FolderWatch() {
    if (fd_ >= 0) ::close(fd_);
  }
  // Waits for an event in `mask` on the entry `name`, skipping others; false when none comes
  // for kHangGuardMs.
  bool wait_for(const std::string& name, uint32_t mask) {
    for (;;) {
      while (!events_.empty()) {
        const auto [what, who] = events_.front();
        events_.pop_front();
        if ((what & mask) && who == name) return true;
      }
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, kHangGuardMs) <= 0) return false;
      alignas(inotify_event) char buf[4096];
      const ssize_t n = ::read(fd_, buf, sizeof buf);
      if (n <= 0) return false;
      for (const char* at = buf; at < buf + n;) {
        const auto* ev = reinterpret_cast<const inotify_event*>(at);
        events_.emplace_back(ev->mask, ev->len > 0 ? std::string(ev->name) : std::string());
        at += sizeof(inotify_event) + ev->len;
      }
    }
  }

 private:
  int fd_;
  std::deque<std::pair<uint32_t, std::string>> events_;  // read, not yet looked at
};

fs::path temp_dir(const std::string& name) {
  fs::path d = fs::temp_directory_path() / ("knit_emu_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

TEST(KnitEmuProgram, KnitsASessionOnAPtyAndRecordsIt) {
  const fs::path dir = temp_dir("session");
  const std::string link = (dir / "ttyKNIT").string(), record = (dir / "rows.txt").string();
  Emulator emu({"--machine", "kh930", "--link", link, "--record", record, "--row-ms", "5", "--boot-ms", "0"});
  const std::string ready = emu.ready_line();
  EXPECT_EQ(ready.rfind("atelier-knit-emu: kh930 on /dev/pts/", 0), 0u) << ready;
  EXPECT_NE(ready.find("linked at " + link), std::string::npos) << ready;
  ASSERT_TRUE(fs::is_symlink(link));
  {
    Port port(link);
    ASSERT_TRUE(port.ok());
    init_and_start(port);
    const std::vector<std::string> rows = {"10000001", "01111110", "00011000"};
    knit(port, rows, 0);
    port.send(line(3, "", true));
    port.send(ab::ReqInfo{});  // the final reqInfo: the last line has been read
    ASSERT_TRUE(port.wait_for<ab::CnfInfo>());
    EXPECT_EQ(read_lines(record), rows);
  }
  EXPECT_EQ(emu.stop(), 0);
  EXPECT_FALSE(fs::exists(fs::symlink_status(link))) << "link left behind after SIGTERM";
  fs::remove_all(dir);
}

TEST(KnitEmuProgram, DropAfterRowRemovesTheLinkAndReplugsAFreshFirmware) {
  const fs::path dir = temp_dir("drop");
  const std::string link = (dir / "ttyKNIT").string(), record = (dir / "rows.txt").string();
  Emulator emu({"--machine", "kh930", "--link", link, "--record", record, "--row-ms", "5", "--boot-ms", "0",
                "--fault", "drop-after-row=2:300"});
  emu.ready_line();
  FolderWatch watch(dir);
  {
    Port port(link);
    ASSERT_TRUE(port.ok());
    init_and_start(port);
    knit(port, {"11000000", "00110000"}, 0);
    EXPECT_TRUE(watch.wait_for("ttyKNIT", IN_DELETE | IN_MOVED_FROM)) << "link still there";
  }
  ASSERT_TRUE(watch.wait_for("ttyKNIT", IN_CREATE | IN_MOVED_TO)) << "link did not come back";
  ASSERT_TRUE(fs::is_symlink(link));
  {
    Port port(link);
    ASSERT_TRUE(port.ok());
    init_and_start(port);  // a fresh firmware accepts reqInit again
    knit(port, {"00001111"}, 0);
  }
  EXPECT_EQ(read_lines(record), (std::vector<std::string>{"11000000", "00110000", "00001111"}));
  EXPECT_EQ(emu.stop(), 0);
  fs::remove_all(dir);
}

// Opens the link and gets as far as knitting (reqStart answered, line 0 asked for), then closes
// the port with no last line, as a host killed mid-job does.
void leave_knitting(const std::string& link) {
  Port port(link);
  ASSERT_TRUE(port.ok());
  init_and_start(port);
}

// The reset edge is the open: closing drops DTR (and says so), the next open resets the board.
TEST(KnitEmuProgram, ReopeningThePortResetsTheFirmware) {
  const fs::path dir = temp_dir("dtr");
  const std::string link = (dir / "ttyKNIT").string();
  Emulator emu({"--machine", "kh930", "--link", link, "--row-ms", "5", "--boot-ms", "0"});
  emu.ready_line();
  leave_knitting(link);
  EXPECT_NE(emu.next_line().find("DTR dropped"), std::string::npos);
  // The next host finds a freshly booted firmware: reqInit is accepted again.
  Port port(link);
  ASSERT_TRUE(port.ok());
  port.send(ab::ReqInit{ab::MachineType::kh930});
  auto init = port.wait_for<ab::CnfInit>();
  ASSERT_TRUE(init);
  EXPECT_EQ(init->error, ab::err::success) << "the firmware was not reset when the host opened the port";
  EXPECT_EQ(emu.stop(), 0);
  fs::remove_all(dir);
}

TEST(KnitEmuProgram, ABadSlipEscapeHangsTheBoardUntilTheHostOpensThePortAgain) {
  const fs::path dir = temp_dir("hang");
  const std::string link = (dir / "ttyKNIT").string();
  Emulator emu({"--machine", "kh930", "--link", link, "--row-ms", "5", "--boot-ms", "0", "--fault",
                "bad-escape-after-row=1"});
  emu.ready_line();
  {
    Port port(link);
    ASSERT_TRUE(port.ok());
    init_and_start(port);
    knit(port, {"10000000"}, 0);  // row 1, and its reqLine(1)
    port.send(line(1, "01000000"));  // taken as ESC + an invalid byte: the board hangs
    port.send(ab::ReqInfo{});
    EXPECT_FALSE(port.wait_for<ab::CnfInfo>([](const ab::CnfInfo&) { return true; }, 300))
        << "a hung board answered";
  }
  EXPECT_NE(emu.next_line().find("DTR dropped"), std::string::npos);  // the emulator saw the close
  Port port(link);  // the open resets the board
  ASSERT_TRUE(port.ok());
  port.send(ab::ReqInfo{});
  EXPECT_TRUE(port.wait_for<ab::CnfInfo>());
  EXPECT_EQ(emu.stop(), 0);
  fs::remove_all(dir);
}

// Without the auto-reset an open finds the firmware as the last host left it.
TEST(KnitEmuProgram, WithNoDtrResetTheFirmwareStaysKnittingAndRefusesToStartAsFirmware1Does) {
  const fs::path dir = temp_dir("nodtr");
  const std::string link = (dir / "ttyKNIT").string();
  Emulator emu({"--machine", "kh930", "--link", link, "--row-ms", "5", "--boot-ms", "0", "--fault", "no-dtr-reset"});
  ASSERT_NE(emu.ready_line().find("linked at"), std::string::npos);
  leave_knitting(link);
  EXPECT_NE(emu.next_line().find("DTR dropped"), std::string::npos);
  Port port(link);
  ASSERT_TRUE(port.ok());
  port.send(ab::ReqInit{ab::MachineType::kh930});
  auto init = port.wait_for<ab::CnfInit>();
  ASSERT_TRUE(init);
  EXPECT_EQ(init->error, ab::err::wrong_machine_state);
  port.send(ab::ReqStart{0, 7, false, false});
  auto start = port.wait_for<ab::CnfStart>();
  ASSERT_TRUE(start);
  EXPECT_EQ(start->error, 0xEF) << "firmware 1.0 answers reqStart outside ready with wrong_machine_state";
  EXPECT_EQ(emu.stop(), 0);
  fs::remove_all(dir);
}

}  // namespace
