// The daemon's pick-up loop: claims what the hot folder reports (and everything at startup)
// through the JobService, hands queued jobs to `enqueue`, and retries a pick-up that failed
// for a transient reason (PickupError::transient: no descriptors, no memory, a full disk, a
// busy store). A retried entry waits 1 s, then 2, 4, ... up to 30 s between tries, until it
// is claimed or has vanished; a lasting failure is logged once and not retried.
//
// Time: the back-off is measured on the Clock given (real_clock() in the daemon; a test
// moves a FakeClock). Threading: one thread (the daemon's main loop). Borrows the hot folder,
// the job service and the clock, which must outlive it.
#pragma once

#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>

#include "base/clock.h"
#include "daemon/hot_folder.h"
#include "daemon/job_service.h"

namespace atelier {

class Pickup {
 public:
  static constexpr std::chrono::seconds kFirstRetry{1};
  static constexpr std::chrono::seconds kLongestRetry{30};

  Pickup(HotFolder& folder, JobService& jobs, std::function<void(int64_t)> enqueue,
         Clock& clock = real_clock());

  // Claims every entry the folder's scan() finds (at startup).
  void scan();
  // Claims what the folder reports now, then every retry that is due. Non-blocking apart
  // from the claims themselves.
  void step();
  // Claims one entry; a transient failure schedules a retry.
  void claim(const std::filesystem::path& entry);

  // How long until the next retry is due (zero if one is due now); nullopt when none waits.
  std::optional<Clock::duration> next_retry_in() const;
  size_t waiting_retries() const { return retries_.size(); }

 private:
  struct Retry {
    Clock::time_point due;
    Clock::duration delay;
  };
  HotFolder& folder_;
  JobService& jobs_;
  std::function<void(int64_t)> enqueue_;
  Clock& clock_;
  std::map<std::filesystem::path, Retry> retries_;
};

}  // namespace atelier
