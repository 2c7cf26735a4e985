// atelierctl end to end: the built binary against a fake daemon (a Unix socket served by a
// thread in this test that records each request and answers canned JSON lines).
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <memory>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::string kCtl = ATELIER_BINARY_DIR "/bin/atelierctl";

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// What the fake daemon writes back for one request: lines in order, then maybe hang up.
struct Reply {
  std::vector<std::string> lines;
  bool close_after = false;
};

Reply ok(const json& result) { return {{json{{"ok", true}, {"result", result}}.dump()}}; }
Reply fail(const std::string& message) {
  return {{json{{"ok", false}, {"error", message}}.dump()}};
}

// Listens on <tmp>/control.sock; serves one connection at a time until destroyed.
class FakeDaemon {
 public:
  explicit FakeDaemon(const fs::path& dir) : path_((dir / "control.sock").string()) {
    listen_fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::snprintf(address.sun_path, sizeof(address.sun_path), "%s", path_.c_str());
    if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0 ||
        ::listen(listen_fd_, 4) != 0 || ::pipe(stop_) != 0) {
      ADD_FAILURE() << "fake daemon cannot listen on " << path_ << ": " << std::strerror(errno);
    }
    thread_ = std::thread([this] { serve(); });
  }
  ~FakeDaemon() {
    char c = 'x';
    (void)!::write(stop_[1], &c, 1);
    thread_.join();
    ::close(listen_fd_);
    ::close(stop_[0]);
    ::close(stop_[1]);
  }

  const std::string& path() const { return path_; }
  void respond(std::function<Reply(const json&)> responder) {
    std::lock_guard lock(mutex_);
    responder_ = std::move(responder);
  }
  std::vector<json> requests() {
    std::lock_guard lock(mutex_);
    return requests_;
  }

 private:
  // False when told to stop.
  bool wait_readable(int fd) {
    pollfd fds[2] = {{fd, POLLIN, 0}, {stop_[0], POLLIN, 0}};
    while (::poll(fds, 2, -1) < 0) {
    }
    return (fds[1].revents & POLLIN) == 0;
  }

  void serve() {
    while (wait_readable(listen_fd_)) {
      int conn = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
      if (conn < 0) continue;
      std::string buffer;
      bool open = true;
      while (open && wait_readable(conn)) {
        char chunk[4096];
        ssize_t n = ::read(conn, chunk, sizeof(chunk));
        if (n <= 0) break;
        buffer.append(chunk, static_cast<std::size_t>(n));
        for (auto nl = buffer.find('\n'); open && nl != std::string::npos;
             nl = buffer.find('\n')) {
          json request = json::parse(buffer.substr(0, nl), nullptr, false);
          buffer.erase(0, nl + 1);
          Reply reply;
          {
            std::lock_guard lock(mutex_);
            requests_.push_back(request);
            reply = responder_ ? responder_(request) : ok(nullptr);
          }
          for (const auto& line : reply.lines) {
            std::string out = line + "\n";
            (void)!::send(conn, out.data(), out.size(), MSG_NOSIGNAL);
          }
          open = !reply.close_after;
        }
      }
      ::close(conn);
    }
  }

  std::string path_;
  int listen_fd_ = -1;
  int stop_[2] = {-1, -1};
  std::thread thread_;
  std::mutex mutex_;
  std::function<Reply(const json&)> responder_;
  std::vector<json> requests_;
};

struct CtlRun {
  int exit_code;
  std::string out;
  std::string err;
};

// atelierctl running in the background (watch), its output in files; SIGTERMed by stop().
class Background {
 public:
  Background(pid_t pid, fs::path out, fs::path err) : pid_(pid), out_(std::move(out)), err_(std::move(err)) {}
  Background(Background&& o) noexcept : pid_(std::exchange(o.pid_, -1)), out_(o.out_), err_(o.err_) {}
  ~Background() { stop(); }
  std::string out() const { return read_file(out_); }
  std::string err() const { return read_file(err_); }
  // Polls stdout every 20 ms for `text`, for at most 30 s.
  bool wait_for_out(const std::string& text) const {
    for (int i = 0; i < 1500; ++i) {
      if (out().find(text) != std::string::npos) return true;
      ::usleep(20000);
    }
    return false;
  }
  // Sends SIGTERM, reaps it, returns its exit code (128 + signal if it was killed).
  int stop() {
    if (pid_ <= 0) return -1;
    ::kill(pid_, SIGTERM);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }

 private:
  pid_t pid_;
  fs::path out_, err_;
};

class AtelierctlTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::exists(kCtl)) << kCtl << " is not built (ninja atelierctl)";
    char pattern[] = "/tmp/atelierctl-test-XXXXXX";
    ASSERT_NE(::mkdtemp(pattern), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    daemon_.reset();
    fs::remove_all(dir_);
  }

  FakeDaemon& daemon() {
    if (!daemon_) daemon_ = std::make_unique<FakeDaemon>(dir_);
    return *daemon_;
  }

  // Runs atelierctl with `args` (shell words) in `cwd`, TZ=UTC so times are predictable,
  // and no inherited ATELIER_SOCKET unless `env` sets one.
  CtlRun ctl(const std::string& args, const std::string& env = "", const fs::path& cwd = "/") {
    fs::path out = dir_ / "stdout", err = dir_ / "stderr";
    std::string command = "cd '" + cwd.string() + "' && env -u ATELIER_SOCKET TZ=UTC " + env +
                          " '" + kCtl + "' " + args + " >'" + out.string() + "' 2>'" +
                          err.string() + "' </dev/null";
    int status = std::system(command.c_str());
    int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return {code, read_file(out), read_file(err)};
  }

  std::string sock() { return "--socket '" + daemon().path() + "' "; }

  // Starts atelierctl `args` (shell words) in the background, TZ=UTC.
  Background start_ctl(const std::string& args) {
    fs::path out = dir_ / "bg-stdout", err = dir_ / "bg-stderr";
    std::string command = "exec env -u ATELIER_SOCKET TZ=UTC '" + kCtl + "' " + args + " >'" +
                          out.string() + "' 2>'" + err.string() + "' </dev/null";
    pid_t pid = ::fork();
    if (pid == 0) {
      ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    return Background(pid, out, err);
  }

  fs::path dir_;
  std::unique_ptr<FakeDaemon> daemon_;
};

json job(int id, const std::string& name, const std::string& state,
         const std::string& reason = "") {
  return {{"id", id},
          {"kind", "knit"},
          {"name", name},
          {"state", state},
          {"reason", reason},
          {"device", ""},
          {"created", "2024-05-01T12:00:00Z"},
          {"updated", "2024-05-01T12:03:04Z"},
          {"output_dir", ""},
          {"progress", {{"done", 30}, {"total", 120}}}};
}

TEST_F(AtelierctlTest, ListJsonPassesServerArrayThrough) {
  json jobs = json::array({job(12, "cat.jpg", "completed"), job(11, "dog.png", "failed", "x")});
  daemon().respond([&](const json&) { return ok(jobs); });
  CtlRun r = ctl(sock() + "list --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out), jobs);
  ASSERT_EQ(daemon().requests().size(), 1u);
  EXPECT_EQ(daemon().requests()[0], (json{{"verb", "list"}, {"args", {{"limit", 1000}}}}));
}

TEST_F(AtelierctlTest, ListStateFilterSendsExactRequest) {
  daemon().respond([](const json& req) {
    if (req["verb"] == "status") return ok({{"kinds", {"knit", "cut"}}});
    return ok({{"jobs", json::array()}, {"total", 0}});
  });
  CtlRun r = ctl(sock() + "list --state failed");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "no jobs\n");
  ASSERT_EQ(daemon().requests().size(), 1u);
  EXPECT_EQ(daemon().requests()[0],
            json::parse(R"({"verb":"list","args":{"state":"failed","limit":1000}})"));

  // A kind is checked against the daemon's kinds first.
  r = ctl(sock() + "list --kind knit --state queued");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(daemon().requests().at(1)["verb"], "status");
  EXPECT_EQ(daemon().requests().at(2),
            json::parse(R"({"verb":"list","args":{"state":"queued","kind":"knit","limit":1000}})"));
}

TEST_F(AtelierctlTest, ListLimitAndAllAskForThatManyAndACutListSaysSo) {
  daemon().respond([](const json& req) {
    const int limit = req["args"]["limit"].get<int>();
    json jobs = json::array();
    for (int id = 5; id > 0 && (limit == 0 || static_cast<int>(jobs.size()) < limit); --id)
      jobs.push_back(job(id, "j" + std::to_string(id) + ".png", "completed"));
    return ok({{"jobs", jobs}, {"total", 5}});
  });
  CtlRun r = ctl(sock() + "list --limit 2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(daemon().requests().at(0)["args"], (json{{"limit", 2}}));
  EXPECT_EQ(lines_of(r.out).size(), 3u) << r.out;  // title + 2 jobs
  EXPECT_EQ(r.err, "showing 2 of 5 jobs; --all for every job\n");

  r = ctl(sock() + "list --all --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(daemon().requests().at(1)["args"], (json{{"limit", 0}}));
  EXPECT_EQ(json::parse(r.out).size(), 5u);  // --json is the array of jobs
  EXPECT_EQ(r.err, "");

  for (const char* bad : {"list --limit 0", "list --limit x", "list --limit 3 --all"}) {
    r = ctl(sock() + bad);
    EXPECT_EQ(r.exit_code, 2) << bad << "\n" << r.err;
  }
  EXPECT_EQ(daemon().requests().size(), 2u);
}

TEST_F(AtelierctlTest, ListOfAnUnknownStateIsAUsageErrorNamingTheStates) {
  daemon();
  CtlRun r = ctl(sock() + "list --state bogus");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  for (const char* state : {"bogus", "queued", "converting", "ready", "running", "completed", "failed",
                            "canceled", "interrupted"})
    EXPECT_NE(r.err.find(state), std::string::npos) << state << " missing in " << r.err;
  EXPECT_TRUE(daemon().requests().empty());
}

TEST_F(AtelierctlTest, ListOfAnUnknownKindIsAUsageErrorNamingTheDaemonsKinds) {
  daemon().respond([](const json&) { return ok({{"kinds", {"knit", "cut", "lace"}}}); });
  CtlRun r = ctl(sock() + "list --kind bogus");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("bogus"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("knit, cut, lace"), std::string::npos) << r.err;
  ASSERT_EQ(daemon().requests().size(), 1u);  // only the question, no list
  EXPECT_EQ(daemon().requests()[0]["verb"], "status");
}

TEST_F(AtelierctlTest, AnUnknownVerbIsNamed) {
  daemon();
  for (const char* args : {"frobnicate", "frobnicate 12", "--socket /x frobnicate"}) {
    CtlRun r = ctl(args);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_NE(r.err.find("unknown verb 'frobnicate'"), std::string::npos) << args << ": " << r.err;
    EXPECT_NE(r.err.find("list"), std::string::npos) << r.err;  // the verbs there are
  }
  EXPECT_TRUE(daemon().requests().empty());
}

TEST_F(AtelierctlTest, CancelAllAsksForEveryJobAndSaysHowMany) {
  daemon().respond([](const json&) {
    return ok({{"jobs", {job(4, "a.png", "canceled", "canceled by user"), job(3, "b.png", "canceled", "canceled by user")}},
               {"canceled", 2},
               {"stopping", 0}});
  });
  CtlRun r = ctl(sock() + "cancel --all");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(daemon().requests().at(0), (json{{"verb", "cancel"}, {"args", {{"all", true}}}}));
  EXPECT_NE(r.out.find("canceled 2 jobs"), std::string::npos) << r.out;
  for (const char* bad : {"cancel", "cancel 3 --all"}) {
    r = ctl(sock() + bad);
    EXPECT_EQ(r.exit_code, 2) << bad << "\n" << r.err;
  }
  EXPECT_EQ(daemon().requests().size(), 1u);
}

TEST_F(AtelierctlTest, ListTableIsAlignedAndTruncatesLongReasons) {
  std::string long_reason(200, 'r');
  daemon().respond([&](const json&) {
    return ok(json::array({job(7, "a-rather-long-name.jpg", "failed", long_reason),
                           job(12, "cat.jpg", "converting")}));
  });
  CtlRun r = ctl(sock() + "list");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto lines = lines_of(r.out);
  ASSERT_EQ(lines.size(), 3u) << r.out;
  for (const char* title : {"ID", "KIND", "STATE", "PROGRESS", "UPDATED", "NAME", "REASON"}) {
    EXPECT_NE(lines[0].find(title), std::string::npos) << title << " missing: " << lines[0];
  }
  // Aligned: each column starts at the same offset on every line.
  auto state_col = lines[0].find("STATE");
  EXPECT_EQ(lines[1].substr(state_col, 6), "failed");
  EXPECT_EQ(lines[2].substr(state_col, 10), "converting");
  auto name_col = lines[0].find("NAME");
  EXPECT_EQ(lines[2].substr(name_col, 7), "cat.jpg");
  EXPECT_NE(lines[2].find("30/120"), std::string::npos);
  EXPECT_NE(lines[2].find("2024-05-01 12:03:04"), std::string::npos);
  // The 200-character reason is cut, and the cut is visible.
  EXPECT_EQ(lines[1].find(long_reason), std::string::npos);
  EXPECT_LT(lines[1].size(), 160u);
  EXPECT_EQ(lines[1].substr(lines[1].size() - 3), "...");
}

TEST_F(AtelierctlTest, SubmitSendsAbsolutePathKindAndSets) {
  fs::create_directories(dir_ / "work" / "sub");
  std::ofstream(dir_ / "work" / "cat.jpg") << "not really a jpeg; the daemon decides";
  daemon().respond([](const json& req) {
    json j = job(42, "cat.jpg", "queued");
    j["kind"] = req["args"]["kind"];
    return ok(j);
  });
  CtlRun r = ctl(sock() + "submit sub/../cat.jpg --kind knit --set max_float=5 --set width=80", "",
              dir_ / "work");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "job 42 cat.jpg: queued\n");
  ASSERT_EQ(daemon().requests().size(), 1u);
  const json req = daemon().requests()[0];  // a copy: requests() returns by value
  EXPECT_EQ(req["verb"], "submit");
  EXPECT_EQ(req["args"]["path"], fs::canonical(dir_ / "work" / "cat.jpg").string());
  EXPECT_EQ(req["args"]["path"].get<std::string>().front(), '/');
  EXPECT_EQ(req["args"]["kind"], "knit");
  EXPECT_EQ(req["args"]["set"], json::array({"max_float=5", "width=80"}));
}

TEST_F(AtelierctlTest, SubmitOfSomethingNotARegularFileFailsAndSendsNothing) {
  const fs::path fifo = dir_ / "pipe.png";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  CtlRun r = ctl(sock() + "submit '" + fifo.string() + "' --kind knit");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("pipe.png: not a regular file"), std::string::npos) << r.err;
  EXPECT_TRUE(daemon().requests().empty());
}

TEST_F(AtelierctlTest, IdVerbsSendIntegerIds) {
  daemon().respond([](const json&) { return ok(job(5, "cat.jpg", "ready")); });
  for (const char* verb : {"start", "cancel", "retry", "frame"}) {
    CtlRun r = ctl(sock() + verb + " 5");
    EXPECT_EQ(r.exit_code, 0) << verb << ": " << r.err;
    EXPECT_EQ(daemon().requests().back(), (json{{"verb", verb}, {"args", {{"id", 5}}}}));
  }
  CtlRun r = ctl(sock() + "resume 5 --from-row 17");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(daemon().requests().back(),
            (json{{"verb", "resume"}, {"args", {{"id", 5}, {"from_row", 17}}}}));
}

TEST_F(AtelierctlTest, StartSendsTheKnittersRowAndNeedle) {
  daemon().respond([](const json&) { return ok(job(5, "cat.jpg", "ready")); });
  CtlRun r = ctl(sock() + "start 5 --from-row 12 --start-needle L20");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(daemon().requests().back(),
            (json{{"verb", "start"}, {"args", {{"id", 5}, {"from_row", 12}, {"start_needle", "L20"}}}}));
  r = ctl(sock() + "start 5 --start-needle 30");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(daemon().requests().back(), (json{{"verb", "start"}, {"args", {{"id", 5}, {"start_needle", "30"}}}}));
  r = ctl(sock() + "start 5 --from-row 0");
  EXPECT_EQ(r.exit_code, 2) << "rows are counted from 1";
  EXPECT_EQ(daemon().requests().size(), 2u);
}

TEST_F(AtelierctlTest, ServerErrorExitsOneWithMessageOnStderr) {
  daemon().respond([](const json&) { return fail("no job with id 99"); });
  CtlRun r = ctl(sock() + "show 99");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no job with id 99"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(daemon().requests().at(0), (json{{"verb", "show"}, {"args", {{"id", 99}}}}));
}

TEST_F(AtelierctlTest, GarbageFromDaemonExitsOne) {
  daemon().respond([](const json&) { return Reply{{"this is not json"}}; });
  CtlRun r = ctl(sock() + "status");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("not JSON"), std::string::npos) << r.err;
}

TEST_F(AtelierctlTest, NoDaemonExitsThreeNamingSocketAndCause) {
  std::string path = (dir_ / "absent.sock").string();
  CtlRun r = ctl("--socket '" + path + "' status");
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find(path), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("No such file or directory"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("is atelierd running?"), std::string::npos) << r.err;
}

TEST_F(AtelierctlTest, StaleSocketExitsThreeWithConnectionRefused) {
  std::string path = (dir_ / "stale.sock").string();
  int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::snprintf(address.sun_path, sizeof(address.sun_path), "%s", path.c_str());
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)), 0);
  ::close(fd);  // the file stays, nobody listens: what a crashed daemon leaves behind
  CtlRun r = ctl("--socket '" + path + "' list");
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("Connection refused"), std::string::npos) << r.err;
}

TEST_F(AtelierctlTest, DaemonHangingUpWithoutAnswerExitsThree) {
  daemon().respond([](const json&) { return Reply{{}, true}; });
  CtlRun r = ctl(sock() + "devices");
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find(daemon().path()), std::string::npos) << r.err;
}

TEST_F(AtelierctlTest, BadUsageExitsTwoAndSendsNothing) {
  daemon();
  for (const char* args : {"", "frobnicate", "show", "show abc", "show 0", "start -3",
                           "submit /etc/hostname", "submit /no/such/file --kind knit",
                           "submit /etc/hostname --kind knit --set novalue",
                           "resume 3 --from-row x", "resume 3 --from-row 0", "list --state",
                           "list --bogus", "wood", "wood remove"}) {
    CtlRun r = ctl(sock() + args);
    EXPECT_EQ(r.exit_code, 2) << "atelierctl " << args << "\n" << r.err;
    EXPECT_FALSE(r.err.empty()) << "atelierctl " << args;
  }
  EXPECT_TRUE(daemon().requests().empty());
}

TEST_F(AtelierctlTest, HelpExitsZero) {
  CtlRun r = ctl("--help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* verb : {"status", "list", "show", "submit", "start", "cancel", "retry",
                           "resume", "hold", "devices", "watch", "frame", "wood"}) {
    EXPECT_NE(r.out.find(verb), std::string::npos) << verb;
  }
}

TEST_F(AtelierctlTest, SocketDefaultsToEnvironment) {
  daemon().respond([](const json&) { return ok(json::array()); });
  CtlRun r = ctl("devices --json", "ATELIER_SOCKET='" + daemon().path() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out), json::array());
  EXPECT_EQ(daemon().requests().at(0), (json{{"verb", "devices"}, {"args", json::object()}}));
}

TEST_F(AtelierctlTest, ShowPrintsFieldsOutputsAndHistory) {
  json j = job(12, "cat.jpg", "completed", "converted");
  j["output_dir"] = "/var/spool/atelier/done/12";
  j["outputs"] = {"pattern.png", "report.json"};
  j["history"] = {{{"at", "2024-05-01T12:00:00Z"}, {"from", ""}, {"to", "queued"}, {"reason", "dropped"}},
                  {{"at", "2024-05-01T12:03:04Z"}, {"from", "converting"}, {"to", "completed"},
                   {"reason", "converted"}}};
  daemon().respond([&](const json&) { return ok(j); });
  CtlRun r = ctl(sock() + "show 12");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* expected :
       {"id:", "12", "state:", "completed", "output_dir:", "/var/spool/atelier/done/12",
        "progress:", "30/120", "outputs:\n  pattern.png\n  report.json\n",
        "history:\n", "2024-05-01 12:00:00  (new) -> queued (dropped)",
        "2024-05-01 12:03:04  converting -> completed (converted)"}) {
    EXPECT_NE(r.out.find(expected), std::string::npos) << expected << " missing in:\n" << r.out;
  }
  r = ctl(sock() + "show 12 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out), j);
}

TEST_F(AtelierctlTest, StatusSummarisesDaemonQueueAndDevices) {
  json status = {{"version", "0.1.0"}, {"pid", 4242},     {"uptime_s", 3725},
                 {"spool", "/var/spool/atelier"}, {"watch", "inotify"}, {"workers", 2},
                 {"queue", {{"queued", 3}, {"failed", 1}, {"completed", 0}}},
                 {"devices", json::array()}};
  daemon().respond([&](const json&) { return ok(status); });
  CtlRun r = ctl(sock() + "status");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* expected : {"pid 4242", "up 1h 02m 05s", "/var/spool/atelier", "3 queued",
                               "1 failed", "no devices configured"}) {
    EXPECT_NE(r.out.find(expected), std::string::npos) << expected << " missing in:\n" << r.out;
  }
  EXPECT_EQ(r.out.find("0 completed"), std::string::npos) << r.out;

  status["devices"] = {{{"name", "knitter"}, {"driver", "ayab"}, {"port", "/dev/ttyACM0"},
                        {"state", "online"}, {"job", 12}}};
  r = ctl(sock() + "status");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.find("no devices configured"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("knitter"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("/dev/ttyACM0"), std::string::npos) << r.out;
}

TEST_F(AtelierctlTest, WatchPrintsOneLinePerEvent) {
  daemon().respond([](const json& req) {
    EXPECT_EQ(req, (json{{"verb", "watch"}, {"args", json::object()}}));
    json done = job(12, "cat.jpg", "completed");
    json failed = job(13, "dog.png", "failed");
    return Reply{{json{{"ok", true}, {"result", "watching"}}.dump(),
                  json{{"event", {{"at", "2024-05-01T12:03:04.100Z"}, {"job", done}, {"from", "converting"},
                                  {"to", "completed"}, {"reason", "converted"}}}}.dump(),
                  json{{"event", {{"at", "2024-05-01T12:05:00.000Z"}, {"job", failed}, {"from", "queued"},
                                  {"to", "failed"}, {"reason", "not an image"}}}}.dump()}};
  });
  Background watch = start_ctl(sock() + "watch");
  ASSERT_TRUE(watch.wait_for_out("dog.png")) << watch.out() << watch.err();
  EXPECT_EQ(lines_of(watch.out()),
            (std::vector<std::string>{
                "2024-05-01 12:03:04 job 12 cat.jpg: converting -> completed (converted)",
                "2024-05-01 12:05:00 job 13 dog.png: queued -> failed (not an image)"}));
  EXPECT_EQ(watch.stop(), 0);  // SIGTERM (as Ctrl-C) ends a watch with success
}

TEST_F(AtelierctlTest, WatchWithNoDaemonExitsThree) {
  CtlRun r = ctl("--socket '" + (dir_ / "nobody.sock").string() + "' watch");
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("nobody.sock"), std::string::npos) << r.err;
}

TEST_F(AtelierctlTest, WatchReconnectsWhenTheDaemonComesBack) {
  int connection = 0;
  daemon().respond([&](const json&) {
    ++connection;
    json event = {{"event",
                   {{"at", "2024-05-01T12:0" + std::to_string(connection) + ":00Z"},
                    {"job", job(20 + connection, "c" + std::to_string(connection) + ".png", "queued")},
                    {"from", ""},
                    {"to", "queued"},
                    {"reason", "dropped"}}}};
    // The first daemon goes away after one event; the one after the restart stays.
    return Reply{{json{{"ok", true}, {"result", "watching"}}.dump(), event.dump()}, connection == 1};
  });
  Background watch = start_ctl(sock() + "watch");
  ASSERT_TRUE(watch.wait_for_out("c2.png")) << watch.out() << "\n" << watch.err();
  EXPECT_NE(watch.out().find("job 21 c1.png: (new) -> queued"), std::string::npos) << watch.out();
  EXPECT_NE(watch.err().find("daemon gone, reconnecting"), std::string::npos) << watch.err();
  EXPECT_NE(watch.err().find("reconnected"), std::string::npos) << watch.err();
  EXPECT_EQ(watch.stop(), 0);
}

}  // namespace
