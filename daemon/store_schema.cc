#include "daemon/store_schema.h"

namespace atelier {

namespace {

// Version 1: jobs, their event history, and the id sequence. States are stored by name so
// the file reads well in the sqlite3 shell. id_sequence holds one row: the last id handed
// out, so ids are never reused even when a job row was never written (crash after reserve).
constexpr const char* kV1 = R"sql(
CREATE TABLE jobs (
  id             INTEGER PRIMARY KEY,
  kind           TEXT    NOT NULL,
  name           TEXT    NOT NULL,
  state          TEXT    NOT NULL,
  reason         TEXT    NOT NULL DEFAULT '',
  device         TEXT    NOT NULL DEFAULT '',
  created_ms     INTEGER NOT NULL,
  updated_ms     INTEGER NOT NULL,
  work_dir       TEXT    NOT NULL DEFAULT '',
  output_dir     TEXT    NOT NULL DEFAULT '',
  params         TEXT    NOT NULL DEFAULT '',
  progress_done  INTEGER NOT NULL DEFAULT 0,
  progress_total INTEGER NOT NULL DEFAULT 0
);
CREATE TABLE events (
  id         INTEGER PRIMARY KEY,
  job_id     INTEGER NOT NULL REFERENCES jobs(id),
  at_ms      INTEGER NOT NULL,
  from_state TEXT,
  to_state   TEXT    NOT NULL,
  reason     TEXT    NOT NULL DEFAULT ''
);
CREATE INDEX events_by_job ON events(job_id);
CREATE TABLE id_sequence (
  one     INTEGER PRIMARY KEY CHECK (one = 1),
  last_id INTEGER NOT NULL
);
INSERT INTO id_sequence (one, last_id) VALUES (1, 0);
)sql";

// Version 2: `atelierctl list --state S` / `--kind K` and counts() filter on these columns;
// the rowid in each index entry keeps "newest first" ordering index-only.
constexpr const char* kV2 = R"sql(
CREATE INDEX jobs_by_state ON jobs(state);
CREATE INDEX jobs_by_kind ON jobs(kind);
)sql";

// Version 3: retention ([store] keep_days, keep_jobs). A purged job's output folder is written
// here in the transaction that deletes its rows, and the entry is dropped once the folder is
// gone from the spool: a crash in between leaves it, and the next purge removes the folder.
constexpr const char* kV3 = R"sql(
CREATE TABLE purged_folders (
  job_id INTEGER PRIMARY KEY,
  path   TEXT    NOT NULL
);
)sql";

// Version 4: the laser console (`atelierctl laser send|unlock|home|jog|origin`): every line an
// operator's command sent to a controller and the controller's reply lines, newest last, for
// `atelierctl laser log`. Kept apart from jobs: retention does not purge it.
constexpr const char* kV4 = R"sql(
CREATE TABLE console_log (
  id     INTEGER PRIMARY KEY,
  at_ms  INTEGER NOT NULL,
  device TEXT    NOT NULL,
  uid    INTEGER NOT NULL,
  line   TEXT    NOT NULL,
  reply  TEXT    NOT NULL DEFAULT ''
);
CREATE INDEX console_log_by_device ON console_log(device, id);
)sql";

}  // namespace

const std::vector<SchemaMigration>& schema_migrations() {
  static const std::vector<SchemaMigration> steps = {
      {1, "jobs, events and id_sequence tables", kV1},
      {2, "indexes on jobs(state) and jobs(kind)", kV2},
      {3, "purged_folders: output folders of purged jobs still to remove", kV3},
      {4, "console_log: lines operators sent to controllers and their replies", kV4},
  };
  return steps;
}

int latest_schema_version() { return schema_migrations().back().to_version; }

}  // namespace atelier
