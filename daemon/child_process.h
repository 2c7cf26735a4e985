// Runs a short helper child (an `atelier-convert` mode that reads something untrusted) under
// limits, so that whatever the input does to it (a crash, a loop, a runaway allocation) costs
// that one request, never the daemon. Collects its stdout and stderr (64 KiB of each at most).
//
// Limits: RLIMIT_AS = `memory_bytes`, RLIMIT_CPU = `cpu_seconds` (CPU time, so a loaded or
// niced box does not fail good input), and SIGKILL after `timeout` of wall time (steady clock).
// The child dies with the daemon (PR_SET_PDEATHSIG) and gets /dev/null as stdin.
// Throws std::system_error when the child cannot be started for now (EMFILE, EAGAIN, ENOMEM).
// Threading: blocks the calling thread for at most `timeout`; any number may run at once.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

namespace atelier {

struct ChildLimits {
  std::chrono::milliseconds timeout{60000};
  int cpu_seconds = 10;
  uint64_t memory_bytes = 512ull << 20;
};

struct ChildResult {
  enum class End { exited, signaled, timed_out } end = End::exited;
  int code = 0;  // the exit code (exited) or the signal (signaled)
  std::string out, err;
  bool ok() const { return end == End::exited && code == 0; }
  bool out_of_cpu() const;  // killed by RLIMIT_CPU
};

// `argv[0]` is the program's path.
ChildResult run_child(const std::vector<std::string>& argv, const ChildLimits& limits);

// The first line of a child's message, trimmed and at most 400 bytes.
std::string first_line(std::string text);

}  // namespace atelier
