// Test helper: a log sink (daemon/log.h) that keeps every record, installed for the helper's
// scope, so a test looks at what the daemon logged - message, priority and job fields -
// without a journal or stderr.
//
// Threading: records may arrive from any thread; the accessors copy under the lock.
// Header-only.
#pragma once

#include <mutex>
#include <string>
#include <vector>

#include "daemon/log.h"

namespace atelier::test {

class LogCapture : public log::Sink {
 public:
  LogCapture() : scope_(*this) {}

  void write(const log::Record& record) override {
    std::lock_guard lock(mu_);
    records_.push_back(record);
  }

  std::vector<log::Record> records() const {
    std::lock_guard lock(mu_);
    return records_;
  }
  // The records whose JOB_ID is `id`, in the order written.
  std::vector<log::Record> for_job(int64_t id) const {
    std::vector<log::Record> out;
    for (const log::Record& r : records())
      if (r.fields.job_id == id) out.push_back(r);
    return out;
  }
  // The STATE= values of job `id`'s records that have one, in order.
  std::vector<std::string> states_of(int64_t id) const {
    std::vector<std::string> out;
    for (const log::Record& r : for_job(id))
      if (!r.fields.state.empty()) out.push_back(r.fields.state);
    return out;
  }

 private:
  mutable std::mutex mu_;
  std::vector<log::Record> records_;
  log::ScopedSink scope_;  // last: installed once the rest exists, removed first
};

}  // namespace atelier::test
