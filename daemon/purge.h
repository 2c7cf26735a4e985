// Purging old finished jobs ([store] keep_days, keep_jobs; the choice: daemon/retention.h):
// their rows and events leave the store, and their output folders (done/<id>/ or failed/<id>/,
// as the store recorded them) leave the spool. Never an unfinished job (is_finished).
//
// Crash safety: Store::purge() deletes the rows and records each folder in one transaction; the
// folder is removed after, and then forgotten. A pass first removes whatever an earlier,
// cut-off pass recorded, so a crash leaves neither a row without its folder being removed nor
// an orphaned folder.
// Safety: only a recorded folder that is exactly <spool>/done/<id> or <spool>/failed/<id> of
// the purged job is removed, opened beneath the spool without following symlinks
// (daemon/remove_tree.h); anything else recorded is left alone and forgotten, with a warning.
// Threading: purge_finished_jobs() may run beside the daemon's other threads (the store
// serialises; the folders are those of finished jobs). PurgeWorker: start() and stop() from
// one thread, wake() from any.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "base/clock.h"
#include "daemon/retention.h"
#include "daemon/spool_layout.h"
#include "daemon/store.h"

namespace atelier {

struct PurgeReport {
  std::vector<int64_t> jobs;          // purged this pass, ascending
  int64_t folders_removed = 0;        // output folders removed (also ones a cut-off pass left)
  std::vector<std::string> problems;  // "FOLDER: problem" for each folder left in place
};

// One pass at wall-clock time `now_ms` (milliseconds since the Unix epoch).
PurgeReport purge_finished_jobs(Store& store, const SpoolLayout& layout, const RetentionPolicy& policy,
                                int64_t now_ms);

// "retention: purged 3 finished jobs (4, 7, 9) ..." for the log; "" when nothing happened.
std::string purge_summary(const PurgeReport& report, const RetentionPolicy& policy);

// Runs a pass at start(), at each wake() and otherwise every `period` on `clock`, on its own thread, with the
// policy `policy()` returns at that moment (so a reloaded config applies at the next pass).
// Each pass's summary is logged (daemon/log.h) and handed to `on_pass` (if any, on the
// worker's thread). The wall-clock time of a pass is now_ms(). The store must outlive it.
class PurgeWorker {
 public:
  PurgeWorker(Store& store, SpoolLayout layout, std::function<RetentionPolicy()> policy,
              Clock& clock = real_clock(), Clock::duration period = std::chrono::hours(1),
              std::function<void(const PurgeReport&)> on_pass = {});
  ~PurgeWorker();  // stop()
  PurgeWorker(const PurgeWorker&) = delete;
  PurgeWorker& operator=(const PurgeWorker&) = delete;

  void start();
  // A pass now rather than at the end of the period (after a reload of the config); the
  // period starts again after it. From any thread.
  void wake();
  // Returns once the worker's thread has ended (a pass under way is finished first).
  void stop();

 private:
  void run();
  Store& store_;
  SpoolLayout layout_;
  std::function<RetentionPolicy()> policy_;
  Clock& clock_;
  Clock::duration period_;
  std::function<void(const PurgeReport&)> on_pass_;
  std::mutex mu_;
  std::condition_variable_any wake_;
  bool stopping_ = false;
  bool woken_ = false;
  std::thread thread_;
};

}  // namespace atelier
