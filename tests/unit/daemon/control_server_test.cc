// The control socket server: descriptors passed with a request (SCM_RIGHTS), the peer's
// credentials, connection caps per uid and in total, the idle timeout (on a FakeClock) and an
// accept loop that does not spin when the process runs out of descriptors.
#include "daemon/control_server.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/fake_clock.h"
#include "tests/e2e/daemon_harness.h"
#include "tests/support/foreign_user.h"
#include "tools/ctl_client.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A raw connection: reads whole lines with a generous real-time bound (never reached when the
// server behaves).
class RawClient {
 public:
  explicit RawClient(const fs::path& socket) {
    fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::snprintf(a.sun_path, sizeof a.sun_path, "%s", socket.c_str());
    connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  }
  ~RawClient() { ::close(fd_); }
  bool connected() const { return connected_; }
  void send(const std::string& text) { (void)!::send(fd_, text.data(), text.size(), MSG_NOSIGNAL); }
  // The next line, or "<eof>" when the server closed, or "<timeout>".
  std::string line() {
    for (;;) {
      if (auto nl = buffer_.find('\n'); nl != std::string::npos) {
        std::string l = buffer_.substr(0, nl);
        buffer_.erase(0, nl + 1);
        return l;
      }
      struct pollfd p = {fd_, POLLIN, 0};
      if (::poll(&p, 1, 20000) <= 0) return "<timeout>";
      char buf[4096];
      ssize_t n = ::read(fd_, buf, sizeof buf);
      if (n <= 0) return "<eof>";
      buffer_.append(buf, static_cast<size_t>(n));
    }
  }

 private:
  int fd_ = -1;
  bool connected_ = false;
  std::string buffer_;
};

class ControlServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ::chmod(dir_.c_str(), 0755);  // the foreign client must reach the socket
  }
  void TearDown() override {
    server_.reset();
  }

  // The handler answers who asked and what each passed file holds.
  void start(ControlLimits limits = {}) {
    server_ = std::make_unique<ControlServer>(
        socket(), "no-such-group-here",
        [](ControlRequest& r) {
          json files = json::array();
          for (const auto& f : r.files) {
            char buf[256];
            ssize_t n = ::pread(f.get(), buf, sizeof buf, 0);
            files.push_back(std::string(buf, n > 0 ? static_cast<size_t>(n) : 0));
          }
          return json{{"verb", r.verb}, {"uid", r.peer.uid}, {"pid", r.peer.pid}, {"files", files}};
        },
        limits, clock_);
    ::chmod(socket().c_str(), 0666);
    server_->start();
  }
  fs::path socket() const { return dir_ / "control.sock"; }

  test::TempDir tmp_;
  const fs::path& dir_ = tmp_.path();
  FakeClock clock_;
  std::unique_ptr<ControlServer> server_;
};

TEST_F(ControlServerTest, FilesPassedWithARequestReachTheHandlerInOrder) {
  start();
  const fs::path a = dir_ / "a.txt", b = dir_ / "b.txt";
  { std::FILE* f = std::fopen(a.c_str(), "w"); std::fputs("first", f); std::fclose(f); }
  { std::FILE* f = std::fopen(b.c_str(), "w"); std::fputs("second", f); std::fclose(f); }
  const int fa = ctl::open_regular_file(a.string()), fb = ctl::open_regular_file(b.string());
  ctl::ControlClient client(socket().string());
  json r = client.request("submit", {{"path", a.string()}}, ctl::ControlClient::kDefaultTimeout, {fa, fb});
  ASSERT_TRUE(r["ok"]) << r;
  EXPECT_EQ(r["result"]["files"], json::array({"first", "second"}));
  // The next request on the same connection carries none: files belong to their own line.
  r = client.request("status", json::object());
  EXPECT_EQ(r["result"]["files"], json::array());
  ::close(fa);
  ::close(fb);
}

TEST_F(ControlServerTest, TheHandlerSeesThePeersUid) {
  start();
  ctl::ControlClient root_client(socket().string());
  EXPECT_EQ(root_client.request("status", json::object())["result"]["uid"], ::geteuid());
  auto run = test::in_child_as_nobody([&](int out) {
    ctl::ControlClient client(socket().string());
    const std::string line = client.request("status", json::object()).dump() + "\n";
    return ::write(out, line.data(), line.size()) > 0 ? 0 : 1;
  });
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(json::parse(run.out)["result"]["uid"], test::kNobody);
}

TEST_F(ControlServerTest, OneUidAtItsCapIsRefusedWhileAnotherUidIsStillServed) {
  ControlLimits limits;
  limits.per_uid = 3;
  limits.total = 5;
  start(limits);
  std::vector<std::unique_ptr<RawClient>> held;
  for (int i = 0; i < 3; ++i) {
    held.push_back(std::make_unique<RawClient>(socket()));
    held.back()->send("{\"verb\": \"status\"}\n");
    ASSERT_NE(held.back()->line().find("\"ok\":true"), std::string::npos);
  }
  // The fourth from the same uid: one line saying why, then closed.
  RawClient extra(socket());
  const std::string refusal = extra.line();
  EXPECT_NE(refusal.find("too many connections from uid " + std::to_string(::geteuid())), std::string::npos)
      << refusal;
  EXPECT_EQ(extra.line(), "<eof>");
  // Someone else still gets in.
  auto run = test::in_child_as_nobody([&](int out) {
    ctl::ControlClient client(socket().string());
    const std::string line = client.request("status", json::object()).dump() + "\n";
    return ::write(out, line.data(), line.size()) > 0 ? 0 : 1;
  });
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(json::parse(run.out)["ok"]) << run.out;
  // The held connections still work.
  held[0]->send("{\"verb\": \"status\"}\n");
  EXPECT_NE(held[0]->line().find("\"ok\":true"), std::string::npos);
}

TEST_F(ControlServerTest, TheTotalCapRefusesTheNextConnectionAndFreesAPlaceOnClose) {
  ControlLimits limits;
  limits.per_uid = 10;
  limits.total = 4;
  start(limits);
  std::vector<std::unique_ptr<RawClient>> held;
  for (int i = 0; i < 4; ++i) {
    held.push_back(std::make_unique<RawClient>(socket()));
    held.back()->send("{\"verb\": \"status\"}\n");
    ASSERT_NE(held.back()->line().find("\"ok\":true"), std::string::npos);
  }
  RawClient extra(socket());
  EXPECT_NE(extra.line().find("too many connections (at most 4)"), std::string::npos);
  EXPECT_EQ(extra.line(), "<eof>");
  held.pop_back();  // closes one
  // The server notices the close when it next wakes; a new client is served then.
  for (int attempt = 0; attempt < 50; ++attempt) {
    RawClient again(socket());
    again.send("{\"verb\": \"status\"}\n");
    const std::string answer = again.line();
    if (answer.find("\"ok\":true") != std::string::npos) return;
    ASSERT_NE(answer.find("too many connections"), std::string::npos) << answer;
  }
  FAIL() << "a freed place was never given to a new client";
}

TEST_F(ControlServerTest, IdleConnectionsAreClosedAfterTheTimeoutButWatchersStay) {
  ControlLimits limits;
  limits.idle_timeout = std::chrono::seconds(60);
  start(limits);
  RawClient idle(socket()), busy(socket()), watcher(socket());
  busy.send("{\"verb\": \"status\"}\n");
  ASSERT_NE(busy.line().find("\"ok\":true"), std::string::npos);
  watcher.send("{\"verb\": \"watch\"}\n");
  ASSERT_NE(watcher.line().find("watching"), std::string::npos);
  idle.send("{\"verb\": \"sta");  // never completes its request
  clock_.advance(std::chrono::seconds(30));
  busy.send("{\"verb\": \"status\"}\n");  // a complete request restarts its 60 s
  ASSERT_NE(busy.line().find("\"ok\":true"), std::string::npos);
  clock_.advance(std::chrono::seconds(31));
  const std::string bye = idle.line();
  EXPECT_NE(bye.find("no request within 60 s"), std::string::npos) << bye;
  EXPECT_EQ(idle.line(), "<eof>");
  // 61 s for the idle one, 31 s since the busy one's last request: it is still served.
  busy.send("{\"verb\": \"status\"}\n");
  EXPECT_NE(busy.line().find("\"ok\":true"), std::string::npos);
  clock_.advance(std::chrono::seconds(120));
  EXPECT_NE(busy.line().find("no request within 60 s"), std::string::npos);
  server_->publish({{"hello", 1}});
  EXPECT_NE(watcher.line().find("hello"), std::string::npos) << "a watcher is never timed out";
}

TEST_F(ControlServerTest, IdleServerDoesNotWakeUp) {
  start();
  std::vector<std::unique_ptr<RawClient>> held;
  for (int i = 0; i < 20; ++i) held.push_back(std::make_unique<RawClient>(socket()));
  held.back()->send("{\"verb\": \"status\"}\n");
  ASSERT_NE(held.back()->line().find("\"ok\":true"), std::string::npos);
  const uint64_t before = server_->wakeups();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(server_->wakeups(), before) << "20 idle connections must not make the loop spin";
}

TEST_F(ControlServerTest, RunningOutOfDescriptorsPausesAcceptingInsteadOfSpinning) {
  ControlLimits limits;
  limits.accept_backoff = std::chrono::milliseconds(100);
  start(limits);
  // Use up the process's descriptors but one, which the client takes: the server's accept()
  // then fails with EMFILE. (A modest limit first, so filling the table is quick.)
  struct rlimit old {};
  ::getrlimit(RLIMIT_NOFILE, &old);
  struct rlimit low = old;
  low.rlim_cur = std::min<rlim_t>(old.rlim_cur, 512);
  ::setrlimit(RLIMIT_NOFILE, &low);
  std::vector<int> filler;
  for (int fd; (fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC)) >= 0;) filler.push_back(fd);
  ASSERT_FALSE(filler.empty());
  ::close(filler.back());
  filler.pop_back();
  auto client = std::make_unique<RawClient>(socket());
  ASSERT_TRUE(client->connected());
  client->send("{\"verb\": \"status\"}\n");
  // Let the server find accept() failing; then it must stay quiet until the clock moves on.
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const uint64_t paused = server_->wakeups();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const uint64_t after = server_->wakeups();
  for (int fd : filler) ::close(fd);
  ::setrlimit(RLIMIT_NOFILE, &old);
  EXPECT_LE(after - paused, 2u) << "the accept loop spun on EMFILE";
  // Descriptors are back and the backoff passes: the waiting client is served.
  clock_.advance(std::chrono::milliseconds(150));
  EXPECT_NE(client->line().find("\"ok\":true"), std::string::npos);
}

TEST_F(ControlServerTest, TooManyFilesWithOneRequestAreRefused) {
  ControlLimits limits;
  limits.max_files = 1;
  start(limits);
  const fs::path a = dir_ / "a.txt";
  { std::FILE* f = std::fopen(a.c_str(), "w"); std::fputs("x", f); std::fclose(f); }
  const int f1 = ctl::open_regular_file(a.string()), f2 = ctl::open_regular_file(a.string());
  ctl::ControlClient client(socket().string());
  json r = client.request("submit", json::object(), ctl::ControlClient::kDefaultTimeout, {f1, f2});
  EXPECT_FALSE(r["ok"]);
  EXPECT_NE(r["error"].get<std::string>().find("at most 1 open files"), std::string::npos) << r;
  ::close(f1);
  ::close(f2);
}

}  // namespace
}  // namespace atelier
