#include "daemon/conversion_runner.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "base/error.h"
#include "convert/common/memory_budget.h"

namespace fs = std::filesystem;

namespace atelier {
namespace {

void close_fd(int& fd) {
  if (fd >= 0) ::close(fd);
  fd = -1;
}

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ' || s.back() == '\r')) s.pop_back();
  // Keep the end: the final error line is the one that explains.
  if (s.size() > 4000) s = "..." + s.substr(s.size() - 4000);
  return s;
}

}  // namespace

SubprocessRunner::SubprocessRunner(fs::path convert_exe, uint64_t memory_limit_bytes, Clock& clock)
    : exe_(std::move(convert_exe)), memory_limit_(memory_limit_bytes), clock_(clock) {}

ConversionOutcome SubprocessRunner::run(const ConversionTask& task,
                                        const std::function<void(double)>& progress,
                                        const std::atomic<bool>& cancel) {
  std::vector<std::string> args = {exe_.string(),         task.kind,
                                   task.input.string(),   task.output_dir.string(),
                                   "--params",            "/dev/stdin",
                                   "--progress-fd",       "3",
                                   "--max-file-bytes",    std::to_string(task.limits.max_file_bytes),
                                   "--max-pixels",        std::to_string(task.limits.max_pixels),
                                   "--memory-mb",         std::to_string(memory_limit_ >> 20)};
  if (task.check_only) args.push_back("--check");
  for (const auto& s : task.sets) {
    args.push_back("--set");
    args.push_back(s);
  }
  for (const auto& dir : task.confine) {
    args.push_back("--confine");
    args.push_back(dir.string());
  }
  for (const auto& [input, output] : task.together) {
    args.push_back("--with");
    args.push_back(input.string());
    args.push_back(output.string());
  }
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  int in_pipe[2], err_pipe[2], prog_pipe[2];
  if (pipe2(in_pipe, O_CLOEXEC) || pipe2(err_pipe, O_CLOEXEC) || pipe2(prog_pipe, O_CLOEXEC))
    return {ConversionOutcome::Status::failed, std::string("pipe: ") + strerror(errno)};

  const pid_t parent = getpid();
  pid_t pid = fork();
  if (pid < 0) return {ConversionOutcome::Status::failed, std::string("fork: ") + strerror(errno)};
  if (pid == 0) {
    // Child: only async-signal-safe calls until exec.
    prctl(PR_SET_PDEATHSIG, SIGKILL);  // never outlive a daemon killed with -9
    if (getppid() != parent) _exit(127);
    dup2(in_pipe[0], 0);
    dup2(err_pipe[1], 2);
    int devnull = open("/dev/null", O_WRONLY);
    if (devnull >= 0) dup2(devnull, 1);
    dup2(prog_pipe[1], 3);
    struct rlimit lim = {memory_limit_, memory_limit_};
    setrlimit(RLIMIT_AS, &lim);
    execv(argv[0], argv.data());
    const char msg[] = "cannot run atelier-convert\n";
    ssize_t ignored = write(2, msg, sizeof msg - 1);
    (void)ignored;
    _exit(127);
  }
  ::close(in_pipe[0]);
  ::close(err_pipe[1]);
  ::close(prog_pipe[1]);
  {
    // A converter that exits before reading its parameters (a bad argument, say) must not kill
    // the caller with SIGPIPE: atelierd ignores it, but a library user (the tests) may not.
    // Block it for this thread around the write and drop the one the write raised.
    sigset_t pipe_signal, old_mask;
    sigemptyset(&pipe_signal);
    sigaddset(&pipe_signal, SIGPIPE);
    pthread_sigmask(SIG_BLOCK, &pipe_signal, &old_mask);
    const ssize_t written = ::write(in_pipe[1], task.defaults_toml.data(), task.defaults_toml.size());
    if (written < 0 && errno == EPIPE) {
      const timespec no_wait{0, 0};
      sigtimedwait(&pipe_signal, nullptr, &no_wait);
    }
    pthread_sigmask(SIG_SETMASK, &old_mask, nullptr);
  }
  close_fd(in_pipe[1]);

  std::string err_text, prog_text;
  const auto deadline = clock_.now() + task.timeout;
  ConversionOutcome::Status stop = ConversionOutcome::Status::ok;
  int err_fd = err_pipe[0], prog_fd = prog_pipe[0];
  while (err_fd >= 0 || prog_fd >= 0) {
    if (cancel.load()) stop = ConversionOutcome::Status::canceled;
    else if (clock_.now() > deadline) stop = ConversionOutcome::Status::timed_out;
    if (stop != ConversionOutcome::Status::ok) {
      kill(pid, SIGKILL);
      break;
    }
    struct pollfd fds[2] = {{err_fd, POLLIN, 0}, {prog_fd, POLLIN, 0}};
    if (poll(fds, 2, 100) < 0 && errno != EINTR) break;
    char buf[4096];
    if (err_fd >= 0 && (fds[0].revents & (POLLIN | POLLHUP | POLLERR))) {
      ssize_t n = ::read(err_fd, buf, sizeof buf);
      if (n <= 0) close_fd(err_fd);
      else err_text.append(buf, static_cast<size_t>(n));
    }
    if (prog_fd >= 0 && (fds[1].revents & (POLLIN | POLLHUP | POLLERR))) {
      ssize_t n = ::read(prog_fd, buf, sizeof buf);
      if (n <= 0) {
        close_fd(prog_fd);
      } else {
        prog_text.append(buf, static_cast<size_t>(n));
        size_t nl;
        while ((nl = prog_text.find('\n')) != std::string::npos) {
          std::string line = prog_text.substr(0, nl);
          prog_text.erase(0, nl + 1);
          if (line.rfind("progress ", 0) == 0 && progress) {
            // Never let a bad line or a failing callback leave the child unreaped.
            try {
              progress(std::stod(line.substr(9)));
            } catch (const std::exception&) {
            }
          }
        }
      }
    }
  }
  close_fd(err_fd);
  close_fd(prog_fd);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (stop == ConversionOutcome::Status::canceled) return {stop, "canceled"};
  if (stop == ConversionOutcome::Status::timed_out)
    return {stop, "conversion took longer than the limit of " +
                      std::to_string(task.timeout.count()) + " s (limits.job_timeout_s)"};
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return {ConversionOutcome::Status::ok, ""};
  std::string message = trim(err_text);
  if (message.rfind("error: ", 0) == 0) message.erase(0, 7);
  // The job folder moves to failed/ afterwards: name files by their own name only.
  const std::string prefix = task.output_dir.string() + "/";
  for (size_t at; (at = message.find(prefix)) != std::string::npos;) message.erase(at, prefix.size());
  if (WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) {
    // Not the runner's kill (timeout and cancel returned above): most likely the kernel's, for
    // memory; an operator's kill -9 looks the same, so the reason says both.
    message = memory_exceeded_reason(task.input.filename().string(), memory_limit_ >> 20) +
              ": the converter was killed (signal 9, by the kernel for memory or from outside)";
  } else if (WIFSIGNALED(status)) {
    message = "the converter stopped with signal " + std::to_string(WTERMSIG(status)) +
              (WTERMSIG(status) == SIGKILL || WTERMSIG(status) == SIGSEGV
                   ? " (out of memory or a crash while decoding " + task.input.filename().string() + ")"
                   : "") +
              (message.empty() ? "" : ": " + message);
  } else if (message.empty()) {
    message = "the converter failed with exit code " + std::to_string(WEXITSTATUS(status));
  }
  return {ConversionOutcome::Status::failed, message};
}

fs::path find_convert_executable() {
  if (const char* env = std::getenv("ATELIER_CONVERT"); env && *env) return env;
  std::error_code ec;
  fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    for (const fs::path& candidate :
         {self.parent_path() / "atelier-convert", self.parent_path() / ".." / "bin" / "atelier-convert"}) {
      if (fs::exists(candidate, ec)) return fs::weakly_canonical(candidate);
    }
  }
  throw InternalError("cannot find atelier-convert beside " + self.string() +
                           " (set ATELIER_CONVERT to its path)");
}

}  // namespace atelier
