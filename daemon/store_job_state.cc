// Job state names, the state machine's allowed edges, and the clock (declared in store.h).
#include <chrono>

#include "daemon/store.h"

namespace atelier {

std::string state_name(JobState s) {
  switch (s) {
    case JobState::queued: return "queued";
    case JobState::converting: return "converting";
    case JobState::ready: return "ready";
    case JobState::running: return "running";
    case JobState::completed: return "completed";
    case JobState::failed: return "failed";
    case JobState::canceled: return "canceled";
    case JobState::interrupted: return "interrupted";
  }
  return "unknown";
}

std::optional<JobState> state_from_name(const std::string& name) {
  for (JobState s : {JobState::queued, JobState::converting, JobState::ready, JobState::running,
                     JobState::completed, JobState::failed, JobState::canceled,
                     JobState::interrupted}) {
    if (state_name(s) == name) return s;
  }
  return std::nullopt;
}

bool transition_allowed(JobState from, JobState to) {
  using S = JobState;
  switch (from) {
    case S::queued:  // failed: rejected at pick-up, before any conversion
      return to == S::converting || to == S::canceled || to == S::failed;
    case S::converting:
      return to == S::ready || to == S::completed || to == S::failed || to == S::canceled ||
             to == S::queued;
    case S::ready: return to == S::running || to == S::completed || to == S::canceled;
    case S::running:
      return to == S::completed || to == S::failed || to == S::canceled || to == S::interrupted;
    case S::failed:
    case S::canceled: return to == S::queued;
    case S::interrupted: return to == S::queued || to == S::running;
    case S::completed: return false;
  }
  return false;
}

bool is_finished(JobState s) {
  return s == JobState::completed || s == JobState::failed || s == JobState::canceled;
}

int64_t now_ms() {
  using namespace std::chrono;
  return duration_cast<milliseconds>(system_clock::now().time_since_epoch()).count();
}

}  // namespace atelier
