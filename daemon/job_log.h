// The story of each job in the log: JobService tells every change (JobChange) and JobLog
// writes it as a record with the job's fields (log::Fields: JOB_ID, KIND, DEVICE, STATE),
// so that `journalctl -u atelierd JOB_ID=12` reads
//   job 12 (knit): queued: cat.jpg, dropped into the hot folder
//   job 12 (knit): converting
//   job 12 (knit): ready: converted; waiting for knitter
//   job 12 (knit, knitter): running: knitting on knitter
//   job 12 (knit, knitter): 10 %: knitting row 21 of 200 ... (at most 9 such lines)
//   job 12 (knit, knitter): completed: knitted 200 rows on knitter
// One record per state change (with STATE= the state entered; failed and interrupted at
// warning priority, the rest at info), one per new reason in the same state (a laser's
// program pause, without STATE=), and progress only when it passes another tenth of the way
// (10 % ... 90 %; the end is the completion).
//
// Threading: on_change() may be called from any thread, also at once from several.
#pragma once

#include <cstdint>
#include <map>
#include <mutex>

#include "daemon/job_service.h"
#include "daemon/log.h"
#include "daemon/store.h"

namespace atelier {

// A job's fields for a record about it: id, kind and device (none until a device takes it),
// and `state` when the record is about a change to that state.
log::Fields job_fields(const Job& job, const std::string& state = "");
// The same for a job known by its id, for records written where only the id is at hand. When
// the store cannot tell (no such job, or the store failing, which may be what is being
// logged), the fields hold the id alone. `device` is set when given.
log::Fields job_fields(Store& store, int64_t id, const std::string& device = "");

class JobLog {
 public:
  // Writes what `change` says, if anything (a progress report between two tenths says
  // nothing).
  void on_change(const JobChange& change);

 private:
  std::mutex mu_;
  std::map<int64_t, int> tenths_;  // per job in its current state: tenths of progress logged
};

}  // namespace atelier
