// How long a job has taken and how long it may still take, for the web page's list
// (docs/web.md: elapsed_s, state_s, time_left_s). Pure; any thread.
#pragma once

#include <cstdint>
#include <optional>

#include "daemon/store.h"

namespace atelier::web {

struct JobTiming {
  double elapsed_s = 0;                // since created; up to its last change once finished
  std::optional<double> state_s;       // in its current state so far (active states only)
  std::optional<double> time_left_s;   // an estimate while it converts or runs
};

// `state_since_ms`: when the job entered its state (from its history), if known.
// `device_time_left_s`: the device's own estimate for a running job (a laser's), if any.
// Without one, a job that has made progress is assumed to go on at the pace it has kept in
// its state: time in state x (total - done) / done.
JobTiming job_timing(const Job& job, std::optional<int64_t> state_since_ms, int64_t now_ms,
                     std::optional<double> device_time_left_s);

// Whether the job is still under way (queued, converting, ready, running): its times grow.
bool is_active(JobState state);

}  // namespace atelier::web
