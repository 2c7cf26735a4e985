// Test helper: knowing that another thread of the test is blocked in a given system call (a
// flock(2) that waits for a lock, a poll(2) inside a read), instead of sleeping and hoping it
// got there. Linux only: reads /proc/self/task/TID/syscall. Header-only.
#pragma once

#include <sys/syscall.h>
#include <unistd.h>

#include <exception>
#include <fstream>
#include <initializer_list>
#include <string>
#include <thread>

namespace atelier::test {

// The calling thread's id, to hand to wait_until_in_syscall() on another thread.
inline pid_t this_thread_id() { return static_cast<pid_t>(::syscall(SYS_gettid)); }

// Returns once thread `tid` of this process is in one of `calls` (SYS_... numbers). Returns
// at once if /proc cannot tell (the thread has ended, or a kernel without the syscall file):
// callers' assertions must hold either way; this only makes sure they test the blocked case.
inline void wait_until_in_syscall(pid_t tid, std::initializer_list<long> calls) {
  const std::string file = "/proc/self/task/" + std::to_string(tid) + "/syscall";
  for (;;) {
    std::ifstream in(file);
    std::string first;  // the call's number, or "running" between calls
    if (!(in >> first)) return;
    if (first != "running") {
      long number = -1;
      try {
        number = std::stol(first);
      } catch (const std::exception&) {
        return;
      }
      for (long call : calls)
        if (number == call) return;
    }
    std::this_thread::yield();
  }
}

}  // namespace atelier::test
