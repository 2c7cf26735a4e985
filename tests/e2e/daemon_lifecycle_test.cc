// The daemon under a service manager: sd_notify messages, SIGHUP reload, SIGTERM stop.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <set>
#include <opencv2/imgcodecs.hpp>

#include "daemon/store.h"
#include "tests/e2e/daemon_harness.h"

namespace fs = std::filesystem;
using atelier::test::DaemonProcess;
using atelier::test::TempDir;

namespace {

// A datagram socket standing in for systemd's NOTIFY_SOCKET.
class FakeNotifySocket {
 public:
  explicit FakeNotifySocket(const fs::path& path) : path_(path) {
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::strncpy(addr.sun_path, path.c_str(), sizeof addr.sun_path - 1);
    if (::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) throw std::runtime_error("bind");
    timeval tv{0, 200000};
    setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  }
  ~FakeNotifySocket() { ::close(fd_); }
  // Everything received so far, messages separated by '\n'.
  std::string drain() {
    char buf[4096];
    ssize_t n;
    while ((n = ::recv(fd_, buf, sizeof buf, 0)) > 0) text_.append(buf, n).push_back('\n');
    return text_;
  }

 private:
  fs::path path_;
  int fd_;
  std::string text_;
};

}  // namespace

TEST(E2EDaemon, NotifiesReadyStatusAndWatchdogThenStopsCleanly) {
  TempDir tmp;
  DaemonProcess daemon(tmp.path());
  FakeNotifySocket notify(tmp.path() / "notify.sock");
  daemon.set_env({"NOTIFY_SOCKET=" + (tmp.path() / "notify.sock").string(), "WATCHDOG_USEC=400000"});
  daemon.start();
  ASSERT_TRUE(daemon.wait_for([&] {
    std::string t = notify.drain();
    return t.find("WATCHDOG=1") != std::string::npos && t.find("STATUS=") != std::string::npos;
  }, std::chrono::seconds(10))) << notify.drain();
  std::string text = notify.drain();
  EXPECT_NE(text.find("READY=1"), std::string::npos) << text;
  // `systemctl status` shows the jobs in each state, those waiting for or on a machine too.
  EXPECT_NE(text.find("STATUS=0 queued, 0 converting, 0 ready, 0 running, 0 completed, 0 failed"), std::string::npos)
      << text;
  EXPECT_EQ(daemon.stop(SIGTERM), 0);
  EXPECT_NE(notify.drain().find("STOPPING=1"), std::string::npos);
  EXPECT_FALSE(fs::exists(daemon.socket())) << "the control socket is removed on exit";
}

TEST(E2EDaemon, SighupReloadsKindDefaultsAndKeepsTheOldConfigWhenTheNewOneIsBad) {
  TempDir tmp;
  DaemonProcess daemon(tmp.path(), "[knit]\nwidth = 40\n");
  daemon.start();
  auto width_of_next_job = [&](const std::string& name) {
    atelier::test::drop_file(atelier::test::test_image("pic1.png"), daemon.incoming("knit") / name);
    EXPECT_TRUE(daemon.wait_for([&] {
      for (const auto& j : daemon.jobs())
        if (j["name"] == name && j["state"] == "completed") return true;
      return false;
    })) << daemon.log();
    for (const auto& j : daemon.jobs())
      if (j["name"] == name)
        return cv::imread(j["output_dir"].get<std::string>() + "/pattern.png").cols;
    return -1;
  };
  EXPECT_EQ(width_of_next_job("a.png"), 40);

  std::ifstream in(daemon.config());
  std::string cfg((std::istreambuf_iterator<char>(in)), {});
  std::string wider = cfg;
  wider.replace(wider.find("width = 40"), 10, "width = 64");
  atelier::test::write_file(daemon.config(), wider);
  kill(daemon.pid(), SIGHUP);
  ASSERT_TRUE(daemon.wait_for([&] { return daemon.log().find("reloaded") != std::string::npos; },
                              std::chrono::seconds(10)));
  EXPECT_EQ(width_of_next_job("b.png"), 64);

  // A typo in the new file: the daemon says so and goes on with what it had.
  atelier::test::write_file(daemon.config(), wider + "[limits]\nworkerz = 3\n");
  kill(daemon.pid(), SIGHUP);
  ASSERT_TRUE(daemon.wait_for([&] { return daemon.log().find("workerz") != std::string::npos; },
                              std::chrono::seconds(10)));
  EXPECT_NE(daemon.log().find("reload failed"), std::string::npos);
  EXPECT_EQ(width_of_next_job("c.png"), 64);
  EXPECT_EQ(daemon.stop(SIGTERM), 0);
}

TEST(E2EDaemon, ConfigErrorsStopTheDaemonWithFileLineAndKey) {
  TempDir tmp;
  fs::path cfg = tmp.path() / "bad.toml";
  atelier::test::write_file(cfg, "[spool]\ndir = \"spool\"\n[knit]\nmax_float = \"four\"\n");
  auto r = atelier::test::run_command({atelier::test::binary("atelierd").string(), "--config", cfg.string()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(cfg.string() + ":4"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("max_float"), std::string::npos) << r.err;
  auto ok = atelier::test::run_command({atelier::test::binary("atelierd").string(), "--check-config",
                                        "--config", (fs::path(ATELIER_SOURCE_DIR) / "config/atelierd.toml").string()});
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
}

TEST(E2EDaemon, ASecondDaemonOnTheSameSpoolIsRefusedAndTheFirstKeepsServing) {
  TempDir tmp;
  DaemonProcess daemon(tmp.path());
  daemon.start();
  auto second = atelier::test::run_command(
      {atelier::test::binary("atelierd").string(), "--config", daemon.config().string()});
  EXPECT_EQ(second.exit_code, 1);
  EXPECT_NE(second.err.find("another atelierd"), std::string::npos) << second.err;
  EXPECT_TRUE(daemon.request("status")["ok"]);
  EXPECT_EQ(daemon.stop(SIGTERM), 0);
}

TEST(E2EDaemon, FinishedJobsPastRetentionArePurgedWithTheirFoldersAtStartUpAndAtOnceOnReload) {
  TempDir tmp;
  DaemonProcess daemon(tmp.path());  // [store] keep_days and keep_jobs at their defaults
  constexpr int64_t kDay = int64_t{24} * 60 * 60 * 1000;
  int64_t old_done = 0, old_failed = 0, recent = 0, interrupted = 0;
  {
    // A store from an earlier run: jobs and their folders where the daemon put them.
    atelier::Store store(tmp.path() / "jobs.sqlite");
    auto add = [&](atelier::JobState state, int64_t age_ms, const char* parent) {
      atelier::Job j;
      j.id = store.reserve_id();
      j.kind = "knit";
      j.name = "cat.png";
      j.state = state;
      j.created_ms = j.updated_ms = atelier::now_ms() - age_ms;
      const fs::path folder = daemon.spool() / parent / std::to_string(j.id);
      j.output_dir = folder.string();
      fs::create_directories(folder);
      atelier::test::write_file(folder / "pattern.png", "png");
      store.insert_job(j);
      return j.id;
    };
    old_done = add(atelier::JobState::completed, 31 * kDay, "done");
    old_failed = add(atelier::JobState::failed, 45 * kDay, "failed");
    recent = add(atelier::JobState::completed, 29 * kDay, "done");
    interrupted = add(atelier::JobState::interrupted, 90 * kDay, "done");  // waits to be resumed
  }
  daemon.start();
  auto ids = [&] {
    std::set<int64_t> out;
    for (const auto& j : daemon.jobs()) out.insert(j["id"].get<int64_t>());
    return out;
  };
  ASSERT_TRUE(daemon.wait_for([&] { return ids().size() == 2; }, std::chrono::seconds(30)))
      << daemon.log();
  EXPECT_EQ(ids(), (std::set<int64_t>{recent, interrupted}));
  EXPECT_FALSE(fs::exists(daemon.spool() / "done" / std::to_string(old_done)));
  EXPECT_FALSE(fs::exists(daemon.spool() / "failed" / std::to_string(old_failed)));
  EXPECT_TRUE(fs::exists(daemon.spool() / "done" / std::to_string(recent) / "pattern.png"));
  EXPECT_TRUE(fs::exists(daemon.spool() / "done" / std::to_string(interrupted) / "pattern.png"));
  EXPECT_TRUE(daemon.wait_for([&] { return daemon.log().find("retention: purged 2 finished jobs") != std::string::npos; },
                              std::chrono::seconds(10)))
      << daemon.log();
  // A reload with a shorter keep_days purges at once, not at the next hour.
  std::string cfg = atelier::test::read_file(daemon.config());
  const std::string store = "[store]\npath = \"jobs.sqlite\"\n";
  ASSERT_NE(cfg.find(store), std::string::npos) << cfg;
  cfg.replace(cfg.find(store), store.size(), store + "keep_days = 28\n");
  atelier::test::write_file(daemon.config(), cfg);
  ::kill(daemon.pid(), SIGHUP);
  ASSERT_TRUE(daemon.wait_for([&] { return ids().size() == 1; }, std::chrono::seconds(30))) << daemon.log();
  EXPECT_EQ(ids(), std::set<int64_t>{interrupted});
  EXPECT_FALSE(fs::exists(daemon.spool() / "done" / std::to_string(recent)));
  EXPECT_EQ(daemon.stop(SIGTERM), 0);
}
