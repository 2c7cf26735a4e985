// The job life cycle on disk and in the store: claiming dropped files (atomic rename into
// work/<id>/ before the job row commits), submitting files, finishing jobs into done/ or
// failed/, and recovering after a crash so that no file is lost or converted twice.
//
// Crash safety: each step is ordered so that any prefix of it is recovered by recover():
//   claim:    reserve id -> mkdir work/<id> + claim.json (name, folder; not yet examined)
//             -> rename the entry in -> examine what was claimed (opened with O_NOFOLLOW,
//             fstat of the descriptor; a job file's kind read by an atelier-convert child)
//             -> move its companions in and examine them -> claim.json rewritten (kind,
//             problem, examined) -> insert row -> fail the job if there is a problem
//   finish:   rename work/<id> to done|failed/<id> -> transition row
// recover() drops a work/<id> without a row whose entry is absent (the rename never
// happened: the entry is still in incoming/), adopts one whose entry is there (examining it
// again when claim.json says it was not yet examined), and fails a row whose claim.json
// names a problem. The entry is examined only once it is in work/<id>/, a folder group
// members cannot write, so nothing can be swapped in between the check and the use.
// Threading: all methods are thread-safe (the store serialises; file moves touch only the
// job's own folders). `on_change` is called after every committed state change, from the
// thread that made it.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "daemon/job_kind_probe.h"
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

// A pick-up that could not be done now. The entry is left where it was in incoming/ (moved
// back if it had been claimed). `transient`: the cause may pass (EMFILE, ENFILE, ENOMEM,
// ENOSPC, EAGAIN, a store error...), so the caller retries; otherwise it is logged only.
class PickupError : public std::runtime_error {
 public:
  PickupError(const std::string& what, bool transient) : std::runtime_error(what), transient_(transient) {}
  bool transient() const noexcept { return transient_; }

 private:
  bool transient_;
};

// True for the errno values of PickupError::transient.
bool is_transient_errno(int err);

class JobService {
 public:
  using ChangeListener = std::function<void(const JobChange&)>;
  // For tests: called between the steps of a claim ("intent": claim.json written, entry not
  // yet renamed; "claimed": renamed into work/<id>/, not yet examined; "examined": about to
  // insert the row). It may throw (e.g. std::system_error(EMFILE)) to inject a failure.
  using ClaimHook = std::function<void(const std::string& step)>;

  // `probe` reads a job file's kind in a child process (default: subprocess_job_kind_probe()).
  JobService(Store& store, SpoolLayout layout, ChangeListener on_change, JobKindProbe probe = {});

  // Creates incoming/<kind> for every known kind, work/, done/, failed/.
  void ensure_layout() const;

  // Claims a file (or symlink, or folder, or FIFO) found in incoming/: renames it into
  // work/<id>/ first, then examines what it claimed. Returns the new job's id; the job is
  // queued, or already failed when the entry can never be converted (symlink, folder, FIFO,
  // not a regular file, a companion that is one of these, unknown kind, file outside a kind
  // folder, a job file that is not one). nullopt if the entry vanished first. Throws
  // PickupError (the entry back in incoming/) when it cannot be claimed now.
  std::optional<int64_t> claim(const std::filesystem::path& entry);
  void set_claim_hook(ClaimHook hook) { claim_hook_ = std::move(hook); }

  // `atelierctl submit`: copies the open file `fd` (opened by the client, with its rights:
  // client_file.h) into a new job named `name` (a bare file name). `params` is the job's
  // `--set` values as stored (job_sets.h). Refuses what is not a regular file and a file larger
  // than `max_bytes`. Throws BadInput naming the file when it cannot be read, is refused or the
  // kind is unknown; the copy is complete before claim.json exists.
  // `reason`: the job's first reason, how it came ("submitted with atelierctl").
  int64_t submit(int fd, const std::string& name, const std::string& kind, const std::string& params,
                 uint64_t max_bytes, const std::string& reason = "submitted with atelierctl");

  // After a start: finishes half-done moves, re-queues interrupted conversions (partial
  // outputs removed), marks running jobs interrupted, adopts claimed files whose row never
  // committed. Returns the ids to queue, oldest first.
  std::vector<int64_t> recover();

  // The claimed input of a queued/converting job (in work/<id>/).
  std::filesystem::path input_of(const Job& job) const;

  // Records progress (no event row; too frequent) and tells the listener, so `watch` shows it.
  void progress(int64_t id, int64_t done, int64_t total, const std::string& what);
  // Progress whose `what` is also the job's reason (no event row), so `show` and `list` say
  // what the running job waits for (e.g. the knitter's next step).
  void progress_reason(int64_t id, int64_t done, int64_t total, const std::string& what);

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

  struct Examined {
    std::string kind;
    std::string problem;  // "" when the job can be converted
  };
  // Examines a claimed entry work/<id>/<name> that came from incoming/<folder> ("" = the top
  // level), and the companions claimed with it. Throws std::system_error for a transient
  // failure (the caller rolls the claim back).
  Examined examine(const std::filesystem::path& work, const std::string& name,
                   const std::string& folder) const;
  std::string examine_companions(const std::filesystem::path& work, const std::string& name) const;
  void step(const std::string& name) const {
    if (claim_hook_) claim_hook_(name);
  }

  Store& store_;
  SpoolLayout layout_;
  ChangeListener on_change_;
  JobKindProbe probe_;
  ClaimHook claim_hook_;
};

}  // namespace atelier
