#include "daemon/pickup.h"

#include <vector>

#include "daemon/log.h"

namespace fs = std::filesystem;

namespace atelier {

Pickup::Pickup(HotFolder& folder, JobService& jobs, std::function<void(int64_t)> enqueue, Clock& clock)
    : folder_(folder), jobs_(jobs), enqueue_(std::move(enqueue)), clock_(clock) {}

void Pickup::scan() {
  for (const auto& entry : folder_.scan()) claim(entry);
}

void Pickup::step() {
  const auto now = clock_.now();
  for (const auto& entry : folder_.collect()) {
    // An entry waiting for its retry is reported again when a failed claim moved it back
    // into incoming/: it keeps its turn, or a lasting EMFILE would spin the loop.
    auto waiting = retries_.find(entry);
    if (waiting == retries_.end() || waiting->second.due <= now) claim(entry);
  }
  std::vector<fs::path> due;
  for (const auto& [path, retry] : retries_)
    if (retry.due <= now) due.push_back(path);
  for (const auto& path : due) claim(path);
}

void Pickup::claim(const fs::path& entry) {
  auto waiting = retries_.find(entry);
  try {
    // The new job, and its failure when it was rejected, are logged by JobLog (job_log.h).
    if (auto id = jobs_.claim(entry)) {
      auto job = jobs_.store().get(*id);
      if (job && job->state == JobState::queued) enqueue_(*id);
    }
    if (waiting != retries_.end()) retries_.erase(waiting);  // claimed, or vanished
  } catch (const PickupError& e) {
    if (!e.transient()) {
      // The file stays where it is: nothing is lost, and a restart tries again.
      log::error(std::string(e.what()) + "; not retried");
      if (waiting != retries_.end()) retries_.erase(waiting);
      return;
    }
    Clock::duration delay = kFirstRetry;
    if (waiting != retries_.end())
      delay = std::min<Clock::duration>(waiting->second.delay * 2, kLongestRetry);
    retries_[entry] = {clock_.now() + delay, delay};
    log::warning(std::string(e.what()) + "; trying again in " +
                 std::to_string(std::chrono::duration_cast<std::chrono::seconds>(delay).count()) + " s");
  } catch (const std::exception& e) {
    log::error(entry.string() + ": cannot pick up: " + e.what());
  }
}

std::optional<Clock::duration> Pickup::next_retry_in() const {
  if (retries_.empty()) return std::nullopt;
  Clock::time_point first = Clock::time_point::max();
  for (const auto& [path, retry] : retries_) first = std::min(first, retry.due);
  const auto now = clock_.now();
  return first <= now ? Clock::duration::zero() : first - now;
}

}  // namespace atelier
