// Asks an `atelier-convert --job-kind FILE` child which kind a job file (incoming/NAME.toml)
// names. The TOML is untrusted and toml++ 3.3.0 crashes on some inputs, so it is never parsed
// inside atelierd: a crash, a hang or a runaway allocation of the child fails that one job,
// with a reason naming the file (and never quoting it).
//
// Limits: the child gets RLIMIT_AS = `memory_bytes` and RLIMIT_CPU = `cpu_seconds` (a parser
// caught in a loop; CPU time, so a loaded or niced box does not fail good files), and is
// SIGKILLed after `timeout` of wall time (steady clock) whatever it does. Reading a job
// file takes about 0.2 s; the pick-up loop waits for it.
// Throws std::system_error when the child cannot be started for now (EMFILE, EAGAIN, ENOMEM:
// the caller retries the pick-up later).
// Threading: blocks the calling thread for at most `timeout`; any number may run at once.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "convert/job_file_kind.h"

namespace atelier {

struct JobKindProbeLimits {
  std::chrono::milliseconds timeout{60000};
  int cpu_seconds = 10;
  uint64_t memory_bytes = 512ull << 20;  // a job file is small: 512 MB is plenty
};

// `exe`: atelier-convert. `file`: the claimed job file; `shown_name` names it in messages.
JobFileKind probe_job_kind(const std::filesystem::path& exe, const std::filesystem::path& file,
                           const std::string& shown_name, const JobKindProbeLimits& limits = {});

// The probe as JobService takes it (daemon/job_service.h).
using JobKindProbe = std::function<JobFileKind(const std::filesystem::path& file, const std::string& shown_name)>;

// probe_job_kind() with the atelier-convert that find_convert_executable() finds (looked up
// at the first job file, so a daemon without one still starts).
JobKindProbe subprocess_job_kind_probe(const JobKindProbeLimits& limits = {});

}  // namespace atelier
