#include "tests/e2e/daemon_harness.h"

#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

extern char** environ;
namespace fs = std::filesystem;

namespace atelier::test {

TempDir::TempDir() {
  std::string tmpl = (fs::temp_directory_path() / "atelier-test-XXXXXX").string();
  if (!mkdtemp(tmpl.data())) throw std::runtime_error("mkdtemp failed");
  path_ = tmpl;
}

TempDir::~TempDir() {
  std::error_code ec;
  fs::remove_all(path_, ec);
}

fs::path binary(const std::string& name) { return fs::path(ATELIER_BINARY_DIR) / "bin" / name; }
fs::path test_image(const std::string& name) { return fs::path(ATELIER_TEST_DATA) / name; }

void write_file(const fs::path& file, const std::string& bytes) {
  std::ofstream out(file, std::ios::binary);
  out << bytes;
}

void drop_file(const fs::path& src, const fs::path& dst) {
  fs::path tmp = dst.parent_path() / ("." + dst.filename().string() + ".part");
  fs::copy_file(src, tmp, fs::copy_options::overwrite_existing);
  fs::rename(tmp, dst);
}

namespace {
std::string slurp(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream buf;
  buf << in.rdbuf();
  return buf.str();
}
}  // namespace

std::string read_file(const fs::path& file) { return slurp(file); }

int free_tcp_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof addr;
  const bool ok = fd >= 0 && ::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0 &&
                  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) == 0;
  if (fd >= 0) ::close(fd);
  if (!ok) throw std::runtime_error("no free TCP port on 127.0.0.1");
  return ntohs(addr.sin_port);
}

CommandResult run_command(const std::vector<std::string>& argv) {
  TempDir tmp;
  fs::path out = tmp.path() / "out", err = tmp.path() / "err";
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&fa, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  std::vector<char*> args;
  std::vector<std::string> copy = argv;
  for (auto& a : copy) args.push_back(a.data());
  args.push_back(nullptr);
  pid_t pid;
  if (posix_spawn(&pid, args[0], &fa, nullptr, args.data(), environ) != 0)
    throw std::runtime_error("cannot run " + argv[0]);
  posix_spawn_file_actions_destroy(&fa);
  int status = 0;
  waitpid(pid, &status, 0);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status), slurp(out), slurp(err)};
}

BackgroundProcess::BackgroundProcess(std::vector<std::string> argv, fs::path log_file) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 1, log_file.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  std::vector<char*> args;
  for (auto& a : argv) args.push_back(a.data());
  args.push_back(nullptr);
  if (posix_spawn(&pid_, args[0], &fa, nullptr, args.data(), environ) != 0)
    throw std::runtime_error("cannot start " + argv[0]);
  posix_spawn_file_actions_destroy(&fa);
}

BackgroundProcess::~BackgroundProcess() { stop(); }

void BackgroundProcess::stop() {
  if (pid_ <= 0) return;
  kill(pid_, SIGTERM);
  waitpid(pid_, nullptr, 0);
  pid_ = -1;
}

DaemonProcess::DaemonProcess(fs::path root, std::string extra_toml) : root_(std::move(root)) {
  std::ofstream cfg(config());
  cfg << "[spool]\ndir = \"spool\"\n[store]\npath = \"jobs.sqlite\"\n[control]\nsocket = \""
      << socket().string() << "\"\n"
      << extra_toml;
}

DaemonProcess::~DaemonProcess() {
  if (pid_ > 0) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
}

fs::path DaemonProcess::incoming(const std::string& kind) const {
  return spool() / "incoming" / kind;
}

std::string DaemonProcess::log() const { return slurp(root_ / "atelierd.log"); }

std::vector<std::string> DaemonProcess::job_log(int64_t id) const {
  const std::string tag = "job " + std::to_string(id) + " (";
  std::vector<std::string> out;
  std::istringstream in(log());
  for (std::string line; std::getline(in, line);) {
    for (const char* level : {"", "warning: ", "error: "}) {
      if (line.rfind(level + tag, 0) == 0) {
        out.push_back(line.substr(std::strlen(level)));
        break;
      }
    }
  }
  return out;
}

void DaemonProcess::start() {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  fs::path log_file = root_ / "atelierd.log";
  posix_spawn_file_actions_addopen(&fa, 2, log_file.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  std::string exe = binary("atelierd").string(), flag = "--config", cfg = config().string();
  char* args[] = {exe.data(), flag.data(), cfg.data(), nullptr};
  // The daemon's signal mask is inherited: make sure it starts with nothing blocked.
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t none;
  sigemptyset(&none);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK);
  std::vector<std::string> env_text = env_;
  for (char** e = environ; *e; ++e) env_text.emplace_back(*e);
  std::vector<char*> envp;
  for (auto& e : env_text) envp.push_back(e.data());
  envp.push_back(nullptr);
  if (posix_spawn(&pid_, exe.c_str(), &fa, &attr, args, envp.data()) != 0)
    throw std::runtime_error("cannot start " + exe);
  posix_spawn_file_actions_destroy(&fa);
  posix_spawnattr_destroy(&attr);
  bool up = wait_for(
      [this] {
        try {
          return request("status").value("ok", false);
        } catch (const std::exception&) {
          return false;
        }
      },
      std::chrono::seconds(20));
  if (!up) throw std::runtime_error("atelierd did not come up:\n" + log());
}

int DaemonProcess::stop(int signal) {
  if (pid_ <= 0) return -1;
  kill(pid_, signal);
  int status = 0;
  waitpid(pid_, &status, 0);
  pid_ = -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status);
}

nlohmann::json DaemonProcess::request(const std::string& verb, const nlohmann::json& args) {
  int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, socket().c_str(), sizeof addr.sun_path - 1);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    throw std::runtime_error("connect: " + std::string(strerror(errno)));
  }
  timeval tv{30, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  std::string line = nlohmann::json{{"verb", verb}, {"args", args}}.dump() + "\n";
  if (::write(fd, line.data(), line.size()) != static_cast<ssize_t>(line.size())) {
    ::close(fd);
    throw std::runtime_error("write failed");
  }
  std::string reply;
  char c;
  while (::read(fd, &c, 1) == 1 && c != '\n') reply.push_back(c);
  ::close(fd);
  return nlohmann::json::parse(reply);
}

nlohmann::json DaemonProcess::jobs() {
  auto r = request("list", {{"limit", 0}});  // 0: every job
  return r.at("result").at("jobs");  // {"jobs": [...], "total": n}
}

bool DaemonProcess::wait_for(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  auto until = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < until) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return done();
}

namespace {
std::vector<std::string> knit_emulator_command(const fs::path& link, const fs::path& record, int row_ms,
                                               const std::vector<std::string>& more) {
  std::vector<std::string> argv{binary("atelier-knit-emu").string(), "--machine", "kh930", "--link",
                                link.string(), "--record", record.string(), "--row-ms", std::to_string(row_ms),
                                "--boot-ms", "50"};
  argv.insert(argv.end(), more.begin(), more.end());
  return argv;
}
}  // namespace

KnitEmulator::KnitEmulator(int row_ms, const std::vector<std::string>& more)
    : link_(dir_.path() / "knitter"),
      record_(dir_.path() / "record.txt"),
      process_(knit_emulator_command(link_, record_, row_ms, more), dir_.path() / "emu.log") {
  for (int i = 0; i < 100 && !fs::exists(link_); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

std::vector<std::string> KnitEmulator::recorded() const {
  std::vector<std::string> rows;
  std::ifstream in(record_);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) rows.push_back(line);
  return rows;
}

nlohmann::json DaemonProcess::job_named(const std::string& name) {
  for (const auto& j : jobs())
    if (j["name"] == name) return j;
  return nullptr;
}

bool DaemonProcess::wait_job_state(const std::string& name, const std::string& state,
                                   std::chrono::milliseconds timeout) {
  return wait_for([&] {
    const nlohmann::json j = job_named(name);
    return !j.is_null() && j["state"] == state;
  }, timeout);
}

bool DaemonProcess::wait_settled(size_t count, std::chrono::milliseconds timeout) {
  return wait_for(
      [&] {
        auto list = jobs();
        if (list.size() < count) return false;
        for (const auto& j : list)
          if (j["state"] == "queued" || j["state"] == "converting") return false;
        return true;
      },
      timeout);
}

}  // namespace atelier::test
