#include "daemon/job_log.h"

#include <algorithm>

namespace atelier {
namespace {

bool finished(const std::string& state) {
  return state == "completed" || state == "failed" || state == "canceled" || state == "interrupted";
}

// "ready: converted; waiting for knitter"; a reason that already begins with the state's name
// ("converting together with job 4", "canceled by user") stands alone.
std::string state_message(const std::string& state, const std::string& reason) {
  if (reason.empty() || reason == state) return state;
  if (reason.rfind(state, 0) == 0) return reason;
  return state + ": " + reason;
}

}  // namespace

log::Fields job_fields(const Job& job, const std::string& state) {
  return {job.id, job.kind, job.device, state};
}

log::Fields job_fields(Store& store, int64_t id, const std::string& device) {
  log::Fields fields{id, "", device, ""};
  try {
    if (auto job = store.get(id)) {
      fields.kind = job->kind;
      if (fields.device.empty()) fields.device = job->device;
    }
  } catch (const std::exception&) {
    // The id alone: the record is likely about this very failure.
  }
  return fields;
}

void JobLog::on_change(const JobChange& change) {
  const Job& job = change.job;
  if (change.progress_only) {
    if (job.progress_total <= 0) return;
    const int tenth = static_cast<int>(std::min<int64_t>(job.progress_done * 10 / job.progress_total, 10));
    {
      std::lock_guard lock(mu_);
      int& logged = tenths_[job.id];
      if (tenth <= logged || tenth >= 10) return;
      logged = tenth;
    }
    log::info(std::to_string(tenth * 10) + " %" + (change.reason.empty() ? "" : ": " + change.reason),
              job_fields(job));
    return;
  }
  if (change.from == change.to) {  // a new reason, same state
    log::info(state_message(change.to, change.reason), job_fields(job));
    return;
  }
  {
    std::lock_guard lock(mu_);
    if (finished(change.to)) {
      tenths_.erase(job.id);
    } else {
      tenths_[job.id] = 0;
    }
  }
  const log::Fields fields = job_fields(job, change.to);
  if (change.from.empty()) {
    // Created: the stored reason says how (the one told may be a pick-up problem, failed next).
    log::info(state_message(change.to, job.name + (job.reason.empty() ? "" : ", " + job.reason)), fields);
    return;
  }
  const log::Priority priority = change.to == "failed" || change.to == "interrupted" ? log::Priority::warning
                                                                                     : log::Priority::info;
  log::write(priority, state_message(change.to, change.reason), fields);
}

}  // namespace atelier
