// Tests that need a client without the test's (root's) rights: a forked child that drops to
// user and group nobody (65534) before doing its part. Header-only; the tests run as root.
#pragma once

#include <fcntl.h>
#include <grp.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <functional>
#include <string>
#include <vector>

namespace atelier::test {

constexpr uid_t kNobody = 65534;

struct ForeignRun {
  int exit_code = -1;  // 128 + signal when killed
  std::string out;     // what the child wrote to its out fd (stdout for a program)
  std::string err;     // its stderr
};

// Runs `body(out_fd)` in a forked child as nobody; its return value is the exit code. Whatever
// it writes to out_fd comes back in `out`. The parent waits for it.
inline ForeignRun in_child_as_nobody(const std::function<int(int out_fd)>& body) {
  int out[2], err[2];
  if (::pipe2(out, O_CLOEXEC) != 0 || ::pipe2(err, O_CLOEXEC) != 0) return {};
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::dup2(err[1], 2);
    if (::setgroups(0, nullptr) != 0 || ::setgid(kNobody) != 0 || ::setuid(kNobody) != 0) _exit(99);
    _exit(body(out[1]));
  }
  ::close(out[1]);
  ::close(err[1]);
  ForeignRun r;
  struct pollfd fds[2] = {{out[0], POLLIN, 0}, {err[0], POLLIN, 0}};
  int open = 2;
  while (open > 0 && ::poll(fds, 2, 60000) > 0) {
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || !(fds[i].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      char buf[4096];
      ssize_t n = ::read(fds[i].fd, buf, sizeof buf);
      if (n <= 0) {
        ::close(fds[i].fd);
        fds[i].fd = -1;
        --open;
      } else {
        (i == 0 ? r.out : r.err).append(buf, static_cast<size_t>(n));
      }
    }
  }
  for (auto& f : fds)
    if (f.fd >= 0) ::close(f.fd);
  int status = 0;
  ::waitpid(pid, &status, 0);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return r;
}

// Runs a program (no shell) as nobody.
inline ForeignRun run_as_nobody(const std::vector<std::string>& argv) {
  return in_child_as_nobody([&](int out_fd) {
    ::dup2(out_fd, 1);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execv(args[0], args.data());
    return 127;
  });
}

}  // namespace atelier::test
