// Test helper: the job changes JobService reports (its ChangeListener), so a test waits for a
// device or the scheduler to move a job by being told, not by polling the store on the real
// clock. Waits end when the change has been seen, or when `within` has passed on the given
// clock - which only happens if something moves that clock (a session on a SimulatedTransport
// does); a wait nothing can end is left to ctest's per-test timeout.
//
// Threading: the listener may be called from any thread; waits from any other. The listener
// must not outlive the JobWatch. Header-only.
#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <set>
#include <vector>

#include "base/clock.h"
#include "daemon/job_service.h"

namespace atelier::test {

class JobWatch {
 public:
  explicit JobWatch(Clock& clock) : clock_(clock) {}

  JobService::ChangeListener listener() {
    return [this](const JobChange& change) {
      {
        std::lock_guard lock(mu_);
        changes_.push_back(change);
      }
      changed_.notify_all();
    };
  }

  // Until a change takes job `id` out of `state` (progress reports and notes do not count).
  bool wait_left(int64_t id, JobState state, Clock::duration within = std::chrono::hours(1)) {
    const std::string from = state_name(state);
    return wait(within, [&] {
      for (const JobChange& c : changes_)
        if (c.job.id == id && c.from == from && c.to != from) return true;
      return false;
    });
  }

  // Until job `id` is, as last reported, in one of `states`. Returns that state, or the last
  // one reported (nullopt: none) if the wait ended otherwise.
  std::optional<JobState> wait_state_in(int64_t id, const std::set<JobState>& states,
                                        Clock::duration within = std::chrono::hours(1)) {
    std::optional<JobState> last;
    wait(within, [&] {
      last.reset();
      for (const JobChange& c : changes_)
        if (c.job.id == id) last = c.job.state;
      return last && states.count(*last) > 0;
    });
    return last;
  }

 private:
  bool wait(Clock::duration within, const std::function<bool()>& seen) {
    std::unique_lock lock(mu_);
    return clock_.wait_for(changed_, lock, within, seen);
  }

  Clock& clock_;
  std::mutex mu_;
  std::condition_variable_any changed_;
  std::vector<JobChange> changes_;
};

}  // namespace atelier::test
