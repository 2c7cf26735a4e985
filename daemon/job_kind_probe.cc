#include "daemon/job_kind_probe.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <memory>
#include <mutex>
#include <optional>
#include <system_error>
#include <vector>

#include "daemon/conversion_runner.h"

namespace fs = std::filesystem;

namespace atelier {
namespace {

std::string first_line(std::string s) {
  if (size_t nl = s.find('\n'); nl != std::string::npos) s.erase(nl);
  while (!s.empty() && (s.back() == '\r' || s.back() == ' ')) s.pop_back();
  if (s.size() > 400) s = s.substr(0, 400) + "...";
  return s;
}

}  // namespace

JobFileKind probe_job_kind(const fs::path& exe, const fs::path& file, const std::string& shown_name,
                           const JobKindProbeLimits& limits) {
  std::string exe_s = exe.string(), flag = "--job-kind", file_s = file.string();
  char* argv[] = {exe_s.data(), flag.data(), file_s.data(), nullptr};
  int out_pipe[2], err_pipe[2];
  if (pipe2(out_pipe, O_CLOEXEC) != 0) throw std::system_error(errno, std::generic_category(), "pipe");
  if (pipe2(err_pipe, O_CLOEXEC) != 0) {
    const int err = errno;
    ::close(out_pipe[0]);
    ::close(out_pipe[1]);
    throw std::system_error(err, std::generic_category(), "pipe");
  }
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) {
    const int err = errno;
    for (int fd : {out_pipe[0], out_pipe[1], err_pipe[0], err_pipe[1]}) ::close(fd);
    throw std::system_error(err, std::generic_category(), "fork");
  }
  if (pid == 0) {
    // Child: only async-signal-safe calls until exec.
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);
    int devnull = open("/dev/null", O_RDONLY);
    if (devnull >= 0) dup2(devnull, 0);
    dup2(out_pipe[1], 1);
    dup2(err_pipe[1], 2);
    struct rlimit lim = {limits.memory_bytes, limits.memory_bytes};
    setrlimit(RLIMIT_AS, &lim);
    struct rlimit cpu = {static_cast<rlim_t>(limits.cpu_seconds), static_cast<rlim_t>(limits.cpu_seconds + 1)};
    setrlimit(RLIMIT_CPU, &cpu);
    execv(argv[0], argv);
    const char msg[] = "cannot run atelier-convert\n";
    ssize_t ignored = write(2, msg, sizeof msg - 1);
    (void)ignored;
    _exit(127);
  }
  ::close(out_pipe[1]);
  ::close(err_pipe[1]);
  std::string out, err;
  int fds_open[2] = {out_pipe[0], err_pipe[0]};
  std::string* sinks[2] = {&out, &err};
  const auto deadline = std::chrono::steady_clock::now() + limits.timeout;
  bool timed_out = false;
  while (fds_open[0] >= 0 || fds_open[1] >= 0) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      timed_out = true;
      kill(pid, SIGKILL);
      break;
    }
    struct pollfd fds[2] = {{fds_open[0], POLLIN, 0}, {fds_open[1], POLLIN, 0}};
    if (poll(fds, 2, static_cast<int>(std::min<int64_t>(left.count(), 100))) < 0 && errno != EINTR) break;
    for (int i = 0; i < 2; ++i) {
      if (fds_open[i] < 0 || !(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      char buf[4096];
      ssize_t n = ::read(fds_open[i], buf, sizeof buf);
      if (n <= 0) {
        ::close(fds_open[i]);
        fds_open[i] = -1;
      } else if (sinks[i]->size() < 65536) {
        sinks[i]->append(buf, static_cast<size_t>(n));
      }
    }
  }
  for (int fd : fds_open)
    if (fd >= 0) ::close(fd);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (timed_out)
    return {"", shown_name + ": reading the job file took longer than " +
                    std::to_string(limits.timeout.count() / 1000.0).substr(0, 4) +
                    " s; is it a TOML job file?"};
  if (WIFSIGNALED(status) && WTERMSIG(status) == SIGXCPU)
    return {"", shown_name + ": reading the job file used more than " + std::to_string(limits.cpu_seconds) +
                    " s of CPU; is it a TOML job file?"};
  if (WIFSIGNALED(status))
    return {"", shown_name + ": the TOML reader stopped with signal " + std::to_string(WTERMSIG(status)) +
                    " while reading the job file (out of memory, or input that crashes it); fix the file"};
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    const std::string kind = first_line(out);
    if (!kind.empty()) return {kind, ""};
    return {"", shown_name + ": the job file's kind could not be read"};
  }
  std::string message = first_line(err);
  if (message.rfind("error: ", 0) == 0) message.erase(0, 7);
  // The child names the file by its own name; anything else it says is dropped rather than
  // passed on, so an unexpected message can never carry the file's content.
  if (message.rfind(shown_name + ":", 0) != 0)
    message = shown_name + ": the job file could not be read (atelier-convert exit code " +
              std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")";
  return {"", message};
}

JobKindProbe subprocess_job_kind_probe(const JobKindProbeLimits& limits) {
  auto exe = std::make_shared<std::optional<fs::path>>();
  auto mu = std::make_shared<std::mutex>();
  return [exe, mu, limits](const fs::path& file, const std::string& shown_name) {
    fs::path path;
    {
      std::lock_guard lock(*mu);
      if (!*exe) *exe = find_convert_executable();
      path = **exe;
    }
    return probe_job_kind(path, file, shown_name, limits);
  };
}

}  // namespace atelier
