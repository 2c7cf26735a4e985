#include "daemon/retention.h"

#include <algorithm>

namespace atelier {

std::vector<int64_t> jobs_to_purge(std::vector<FinishedJob> finished, const RetentionPolicy& policy,
                                   int64_t now_ms) {
  constexpr int64_t kDayMs = int64_t{24} * 60 * 60 * 1000;
  // Newest first: the first keep_jobs are the ones kept by count.
  std::sort(finished.begin(), finished.end(), [](const FinishedJob& a, const FinishedJob& b) {
    return a.finished_ms != b.finished_ms ? a.finished_ms > b.finished_ms : a.id > b.id;
  });
  std::vector<int64_t> out;
  for (size_t i = 0; i < finished.size(); ++i) {
    const bool too_many = policy.keep_jobs > 0 && i >= static_cast<size_t>(policy.keep_jobs);
    const bool too_old = policy.keep_days > 0 && now_ms - finished[i].finished_ms > policy.keep_days * kDayMs;
    if (too_many || too_old) out.push_back(finished[i].id);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace atelier
