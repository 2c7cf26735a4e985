// Test harness: runs the real atelierd binary on a temporary spool and talks to it over
// its control socket, as atelierctl does. One instance per test; not thread-safe.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace atelier::test {

// A fresh temporary folder, removed when the object dies.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

std::filesystem::path binary(const std::string& name);  // <build>/bin/<name>
std::filesystem::path test_image(const std::string& name);  // tests/data/<name>

// Copies `src` to `dst` the way a careful user drops a file: under a temporary name in the
// same folder, then renamed into place.
void drop_file(const std::filesystem::path& src, const std::filesystem::path& dst);
void write_file(const std::filesystem::path& file, const std::string& bytes);
std::string read_file(const std::filesystem::path& file);  // "" when it cannot be read

struct CommandResult {
  int exit_code;
  std::string out;
  std::string err;
};
// A TCP port on 127.0.0.1 that was free a moment ago (bound to 0, read back, closed).
int free_tcp_port();

// Runs a program with arguments (no shell) and collects its output.
CommandResult run_command(const std::vector<std::string>& argv);

// A background program (e.g. a machine emulator), SIGTERMed and reaped on destruction.
class BackgroundProcess {
 public:
  BackgroundProcess(std::vector<std::string> argv, std::filesystem::path log_file);
  ~BackgroundProcess();
  void stop();
  pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = -1;
};

// The knitting-machine emulator (a KH930) on a link in its own temporary folder, recording the
// needles of every pass it is sent; ready (its link there) once constructed, or after 5 s.
// `row_ms`: how long a pass takes; `more`: further options (e.g. "--fault", "api=5").
class KnitEmulator {
 public:
  explicit KnitEmulator(int row_ms = 3, const std::vector<std::string>& more = {});
  const std::filesystem::path& link() const { return link_; }
  // The passes recorded so far, one needle string (0/1, working range) each.
  std::vector<std::string> recorded() const;

 private:
  TempDir dir_;
  std::filesystem::path link_, record_;
  BackgroundProcess process_;
};

class DaemonProcess {
 public:
  // Writes <root>/atelierd.toml with the spool, store and socket inside `root`, plus
  // `extra_toml` appended (e.g. "[limits]\nworkers = 1\n").
  DaemonProcess(std::filesystem::path root, std::string extra_toml = "");
  ~DaemonProcess();  // SIGKILLs a daemon still running

  void start();                 // waits until the control socket answers
  // Extra environment ("NAME=value") for the next start(), e.g. NOTIFY_SOCKET.
  void set_env(std::vector<std::string> env) { env_ = std::move(env); }
  pid_t pid() const { return pid_; }
  int stop(int signal = 15);    // sends `signal`, waits, returns exit code (-signal if killed)
  bool running() const { return pid_ > 0; }

  std::filesystem::path spool() const { return root_ / "spool"; }
  std::filesystem::path incoming(const std::string& kind) const;
  std::filesystem::path socket() const { return root_ / "control.sock"; }
  std::filesystem::path config() const { return root_ / "atelierd.toml"; }
  std::string log() const;      // the daemon's stderr so far
  // The lines of log() about job `id` ("job 12 (knit): ...", also after "warning: " or
  // "error: "): the job's story as the journal's JOB_ID=12 would show it.
  std::vector<std::string> job_log(int64_t id) const;

  // One control request; returns the response object ({"ok":..., ...}).
  nlohmann::json request(const std::string& verb, const nlohmann::json& args = nlohmann::json::object());
  nlohmann::json jobs();        // list, newest first (result array)

  // Polls `done` every 50 ms until it returns true or `timeout` passes.
  bool wait_for(const std::function<bool()>& done,
                std::chrono::milliseconds timeout = std::chrono::seconds(120));
  // The newest job named `name` (its file name), or null.
  nlohmann::json job_named(const std::string& name);
  // Waits until the job named `name` exists and is in `state`.
  bool wait_job_state(const std::string& name, const std::string& state,
                      std::chrono::milliseconds timeout = std::chrono::seconds(90));
  // Waits until `count` jobs exist and none is queued or converting.
  bool wait_settled(size_t count, std::chrono::milliseconds timeout = std::chrono::seconds(180));

 private:
  std::filesystem::path root_;
  pid_t pid_ = -1;
  std::vector<std::string> env_;
};

}  // namespace atelier::test
