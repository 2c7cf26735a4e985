// Job state names, the state machine's allowed edges, and the clock (declared in store.h).
#include <chrono>

#include "base/job_states.h"
#include "daemon/store.h"

namespace atelier {

static_assert(kJobStateNames.size() == static_cast<size_t>(JobState::interrupted) + 1,
              "base/job_states.h lists every JobState, in the enum's order");

std::string state_name(JobState s) {
  const auto i = static_cast<size_t>(s);
  return i < kJobStateNames.size() ? std::string(kJobStateNames[i]) : "unknown";
}

std::optional<JobState> state_from_name(const std::string& name) {
  for (size_t i = 0; i < kJobStateNames.size(); ++i)
    if (kJobStateNames[i] == name) return static_cast<JobState>(i);
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
