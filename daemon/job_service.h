// The job life cycle on disk and in the store: claiming dropped files (atomic rename into
// work/<id>/ before the job row commits), submitting files, finishing jobs into done/ or
// failed/, and recovering after a crash so that no file is lost or converted twice.
//
// Crash safety: each step is ordered so that any prefix of it is recovered by recover():
//   claim:    reserve id -> mkdir work/<id> + claim.json -> rename file in -> insert row
//   finish:   rename work/<id> to done|failed/<id> -> transition row
// Threading: all methods are thread-safe (the store serialises; file moves touch only the
// job's own folders). `on_change` is called after every committed state change, from the
// thread that made it.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "daemon/spool_layout.h"
#include "daemon/store.h"

namespace atelier {

struct JobChange {
  Job job;           // after the change
  std::string from;  // previous state, "" when created
  std::string to;
  std::string reason;
  bool progress_only = false;  // no state change: the job moved on (e.g. a row was knitted)
};

class JobService {
 public:
  using ChangeListener = std::function<void(const JobChange&)>;

  JobService(Store& store, SpoolLayout layout, ChangeListener on_change);

  // Creates incoming/<kind> for every known kind, work/, done/, failed/.
  void ensure_layout() const;

  // Claims a file (or symlink, or folder) found in incoming/. Returns the new job's id; the
  // job is queued, or already failed when the entry can never be converted (symlink, folder,
  // unknown kind, file outside a kind folder). nullopt if the entry vanished first.
  std::optional<int64_t> claim(const std::filesystem::path& entry);

  // `atelierctl submit`: copies the open file `fd` (opened by the client, with its rights:
  // client_file.h) into a new job named `name` (a bare file name). `params` is the job's
  // `--set` values as stored (job_sets.h). Refuses what is not a regular file and a file larger
  // than `max_bytes`. Throws BadInput naming the file when it cannot be read, is refused or the
  // kind is unknown; the copy is complete before claim.json exists.
  int64_t submit(int fd, const std::string& name, const std::string& kind, const std::string& params,
                 uint64_t max_bytes);

  // After a start: finishes half-done moves, re-queues interrupted conversions (partial
  // outputs removed), marks running jobs interrupted, adopts claimed files whose row never
  // committed. Returns the ids to queue, oldest first.
  std::vector<int64_t> recover();

  // The claimed input of a queued/converting job (in work/<id>/).
  std::filesystem::path input_of(const Job& job) const;

  // Records progress (no event row; too frequent) and tells the listener, so `watch` shows it.
  void progress(int64_t id, int64_t done, int64_t total, const std::string& what);

  // A new reason without a state change (Store::note), told to the listener like a change.
  void note(int64_t id, const std::string& reason);

  // State changes (each one store transaction, then on_change).
  void transition(int64_t id, JobState to, const std::string& reason,
                  const std::optional<std::string>& device = std::nullopt);
  // Moves work/<id> to done/<id> and marks the job completed (or `to`, e.g. ready).
  void finish_converted(int64_t id, JobState to, const std::string& reason);
  // Writes reason.txt, removes partial outputs, moves work/<id> to failed/<id>, marks the
  // job `to` (failed, or canceled: a canceled job's input is kept in failed/<id> too).
  void fail(int64_t id, const std::string& reason, JobState to = JobState::failed);
  // Removes partial outputs of an interrupted conversion and re-queues the job.
  void requeue(int64_t id, const std::string& reason);
  // failed/interrupted/canceled -> queued: moves the input back into work/<id>.
  void retry(int64_t id);

  Store& store() { return store_; }
  const SpoolLayout& layout() const { return layout_; }

 private:
  void insert(const Job& job);
  // A job whose folder reached done/ or failed/ but whose row was not updated (crash between
  // the two): records the state written in the folder's finish.json. False if neither exists.
  bool finish_cut_off_move(const Job& job);
  void clean_partial_outputs(const Job& job) const;
  // The shared end of finish_converted() and fail(): work/<id> -> `folder`, row -> `to`.
  void move_and_record(const Job& job, const std::filesystem::path& folder, JobState to,
                       const std::string& reason);

  Store& store_;
  SpoolLayout layout_;
  ChangeListener on_change_;
};

}  // namespace atelier
