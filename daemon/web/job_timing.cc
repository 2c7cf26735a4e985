#include "daemon/web/job_timing.h"

#include <algorithm>

namespace atelier::web {

bool is_active(JobState s) {
  return s == JobState::queued || s == JobState::converting || s == JobState::ready || s == JobState::running;
}

JobTiming job_timing(const Job& job, std::optional<int64_t> state_since_ms, int64_t now_ms,
                     std::optional<double> device_time_left_s) {
  JobTiming t;
  const bool active = is_active(job.state);
  const int64_t end_ms = active ? now_ms : job.updated_ms;
  t.elapsed_s = std::max<int64_t>(0, end_ms - job.created_ms) / 1000.0;
  if (!active) return t;
  if (state_since_ms) t.state_s = std::max<int64_t>(0, now_ms - *state_since_ms) / 1000.0;
  if (job.state == JobState::running && device_time_left_s) {
    t.time_left_s = std::max(0.0, *device_time_left_s);
    return t;
  }
  const bool moving = job.state == JobState::converting || job.state == JobState::running;
  if (moving && t.state_s && job.progress_done > 0 && job.progress_total > job.progress_done)
    t.time_left_s = *t.state_s * static_cast<double>(job.progress_total - job.progress_done) /
                    static_cast<double>(job.progress_done);
  return t;
}

}  // namespace atelier::web
