// The job store: SQLite in WAL mode, a versioned schema with migrations, one transaction
// per state change, and an events table holding each job's history.
//
// Thread-safe: one connection guarded by a mutex (SQLite work here is small and short).
// Times are milliseconds since the Unix epoch (UTC). Errors throw StoreError.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/error.h"

struct sqlite3;

namespace atelier {

class StoreError : public InternalError {
 public:
  using InternalError::InternalError;
};

// In the order of base/job_states.h (kJobStateNames), which names them.
enum class JobState { queued, converting, ready, running, completed, failed, canceled, interrupted };

std::string state_name(JobState s);                       // "queued", ...
std::optional<JobState> state_from_name(const std::string& name);
// True for the allowed edges of the job state machine (DESIGN.md "Job states"):
// queued->converting|canceled|failed; converting->ready|completed|failed|canceled|queued;
// ready->running|completed|canceled; running->completed|failed|canceled|interrupted;
// failed|interrupted|canceled->queued (retry); interrupted->running (resume).
bool transition_allowed(JobState from, JobState to);
// Completed, failed or canceled: nothing more happens to the job unless an operator retries
// it, so retention ([store] keep_days, keep_jobs) may purge it. Interrupted is not finished
// (a knitting job waits there to be resumed from a row), nor is any state before.
bool is_finished(JobState s);

struct Job {
  int64_t id = 0;
  std::string kind;
  std::string name;          // the dropped file's name, e.g. "cat.jpg"
  JobState state = JobState::queued;
  std::string reason;        // why it is in its state (failure reason, "canceled by user")
  std::string device;        // device name, empty when none
  int64_t created_ms = 0;
  int64_t updated_ms = 0;
  std::string work_dir;      // folder holding the claimed input while queued/converting
  std::string output_dir;    // done/<id> or failed/<id> once finished, else empty
  std::string params;        // TOML text of the job's own overrides (sidecar, --set)
  int64_t progress_done = 0;
  int64_t progress_total = 0;
};

struct JobEvent {
  int64_t job_id = 0;
  int64_t at_ms = 0;
  std::string from;  // empty for the creation event
  std::string to;
  std::string reason;
};

// A finished job as retention sees it (daemon/retention.h).
struct FinishedJob {
  int64_t id = 0;
  int64_t finished_ms = 0;  // its last change (updated_ms): when it finished
};

// The output folder of a purged job, still to be removed from the spool.
struct PurgedFolder {
  int64_t job_id = 0;
  std::string path;  // as recorded in the job's output_dir
};

// One line an operator's laser command sent to a controller (`atelierctl laser ...`).
struct ConsoleLine {
  int64_t id = 0;
  int64_t at_ms = 0;
  std::string device;  // [[device]] name
  int64_t uid = -1;    // the client's uid (-1: unknown)
  std::string line;    // as sent, without its newline
  std::string reply;   // the controller's reply lines, "\n"-joined (up to its ok/error:N)
};

struct JobFilter {
  std::optional<JobState> state;
  std::optional<std::string> kind;
  int64_t limit = 1000;  // the newest `limit` jobs; negative: every job (count() ignores it)
  int64_t offset = 0;    // skip this many of the newest first (paging; count() ignores it)
};

class Store {
 public:
  // Opens or creates the database, sets WAL mode and busy timeout, and migrates the schema
  // to the latest version. Creates the parent folder if missing.
  explicit Store(const std::filesystem::path& db_file);
  ~Store();
  Store(const Store&) = delete;
  Store& operator=(const Store&) = delete;

  int schema_version();

  // Reserves a fresh job id (committed at once, never reused, even after a crash).
  int64_t reserve_id();

  // Inserts a job with a reserved id in state `job.state` (normally queued) and its creation
  // event, in one transaction. Throws StoreError if the id already has a job.
  void insert_job(const Job& job);
  bool has_job(int64_t id);

  // One transaction: checks the edge is allowed (else throws StoreError), updates the job's
  // state, reason and updated time, and appends an event. Optional fields are set when given.
  void transition(int64_t id, JobState to, const std::string& reason,
                  const std::optional<std::string>& output_dir = std::nullopt,
                  const std::optional<std::string>& device = std::nullopt);

  // A new reason in the same state (e.g. a running laser job paused by its program), with
  // an event from the state to itself so the history shows it. Throws StoreError if no job.
  void note(int64_t id, const std::string& reason);

  // Progress does not make an event (it changes too often).
  void set_progress(int64_t id, int64_t done, int64_t total);
  // The same, and a new reason without an event (what a running job is doing now, e.g. the
  // knitter's next step; too frequent for the history).
  void set_progress(int64_t id, int64_t done, int64_t total, const std::string& reason);

  std::optional<Job> get(int64_t id);
  std::vector<Job> list(const JobFilter& filter);     // newest first (id descending)
  int64_t count(const JobFilter& filter);             // jobs matching state and kind, any limit
  std::vector<JobEvent> history(int64_t id);          // oldest first
  std::map<JobState, int64_t> counts();               // every state, zero included

  // Retention (daemon/retention.h chooses the jobs, daemon/purge.h removes their folders).
  // Every finished job (is_finished), in id order.
  std::vector<FinishedJob> finished_jobs();
  // One transaction: deletes each job of `ids` that is still finished (an unfinished or
  // unknown one is skipped), its events with it, and records its output folder (if it has
  // one) in purged_folders. Returns the ids deleted, ascending.
  std::vector<int64_t> purge(const std::vector<int64_t>& ids);
  // The folders purge() recorded and forget_purged_folder() has not yet dropped, by job id.
  std::vector<PurgedFolder> purged_folders();
  void forget_purged_folder(int64_t job_id);

  // The laser console log (schema v4). Returns the new row's id.
  int64_t add_console_line(const ConsoleLine& line);
  // The last `limit` lines (of `device`, or of every device when empty), oldest first.
  std::vector<ConsoleLine> console_lines(const std::string& device, int64_t limit);

 private:
  void exec(const char* sql);
  void migrate();
  sqlite3* db_ = nullptr;
  std::mutex mu_;
};

// Milliseconds since the Unix epoch, now.
int64_t now_ms();

}  // namespace atelier
