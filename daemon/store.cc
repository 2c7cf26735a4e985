#include "daemon/store.h"

#include <sqlite3.h>

#include <algorithm>

#include "daemon/store_schema.h"

namespace atelier {

namespace {

constexpr const char* kJobColumns =
    "id, kind, name, state, reason, device, created_ms, updated_ms, work_dir, output_dir, "
    "params, progress_done, progress_total";

// The file the connection has open (absolute), for error messages.
std::string db_path(sqlite3* db) {
  const char* name = sqlite3_db_filename(db, "main");
  return name && *name ? name : "(unnamed database)";
}

[[noreturn]] void fail(sqlite3* db, const std::string& what) {
  throw StoreError("store " + db_path(db) + ": " + what);
}

// A failed SQLite call: names the file, what was being done, and SQLite's own message.
[[noreturn]] void fail_sqlite(sqlite3* db, const std::string& what) {
  throw StoreError("store " + db_path(db) + ": " + what + ": " + sqlite3_errmsg(db));
}

void exec_sql(sqlite3* db, const char* sql, const std::string& what) {
  if (sqlite3_exec(db, sql, nullptr, nullptr, nullptr) != SQLITE_OK) fail_sqlite(db, what);
}

// One prepared statement with bound parameters; finalized when it leaves scope.
class Stmt {
 public:
  Stmt(sqlite3* db, const std::string& sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql.c_str(), static_cast<int>(sql.size()), &st_, nullptr) !=
        SQLITE_OK) {
      fail_sqlite(db, "preparing \"" + sql + "\"");
    }
  }
  ~Stmt() { sqlite3_finalize(st_); }
  Stmt(const Stmt&) = delete;
  Stmt& operator=(const Stmt&) = delete;

  // Parameters are numbered from 1, as in SQLite.
  Stmt& bind(int i, int64_t v) {
    check(sqlite3_bind_int64(st_, i, v));
    return *this;
  }
  Stmt& bind(int i, const std::string& v) {
    check(sqlite3_bind_text(st_, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT));
    return *this;
  }
  Stmt& bind(int i, const std::optional<std::string>& v) {
    if (v) return bind(i, *v);
    check(sqlite3_bind_null(st_, i));
    return *this;
  }

  // True when a row is available, false when the statement has finished.
  bool step() {
    int rc = sqlite3_step(st_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    fail_sqlite(db_, std::string("running \"") + sqlite3_sql(st_) + "\"");
  }
  void run() {
    while (step()) {
    }
  }

  // Columns are numbered from 0.
  int64_t integer(int i) { return sqlite3_column_int64(st_, i); }
  bool is_null(int i) { return sqlite3_column_type(st_, i) == SQLITE_NULL; }
  std::string text(int i) {
    const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(st_, i));
    return p ? std::string(p, static_cast<size_t>(sqlite3_column_bytes(st_, i))) : std::string();
  }

 private:
  void check(int rc) {
    if (rc != SQLITE_OK) fail_sqlite(db_, std::string("binding a value for \"") + sqlite3_sql(st_) + "\"");
  }
  sqlite3* db_;
  sqlite3_stmt* st_ = nullptr;
};

// BEGIN IMMEDIATE takes the write lock up front, so a read-then-write never hits a lock
// upgrade deadlock. Rolled back unless commit() succeeds.
class Transaction {
 public:
  explicit Transaction(sqlite3* db) : db_(db) {
    exec_sql(db_, "BEGIN IMMEDIATE", "starting a transaction");
  }
  ~Transaction() {
    if (!committed_) sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
  }
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit() {
    exec_sql(db_, "COMMIT", "committing a transaction");
    committed_ = true;
  }

 private:
  sqlite3* db_;
  bool committed_ = false;
};

int read_user_version(sqlite3* db) {
  Stmt s(db, "PRAGMA user_version");
  if (!s.step()) fail_sqlite(db, "reading the schema version");
  return static_cast<int>(s.integer(0));
}

// `where` says which row held the name, e.g. "job 7".
JobState parse_state(sqlite3* db, const std::string& name, const std::string& where) {
  auto s = state_from_name(name);
  if (!s) fail(db, where + " has unknown state '" + name + "'");
  return *s;
}

// Reads a row selected with kJobColumns.
Job read_job(sqlite3* db, Stmt& s) {
  Job j;
  j.id = s.integer(0);
  j.kind = s.text(1);
  j.name = s.text(2);
  j.state = parse_state(db, s.text(3), "job " + std::to_string(j.id));
  j.reason = s.text(4);
  j.device = s.text(5);
  j.created_ms = s.integer(6);
  j.updated_ms = s.integer(7);
  j.work_dir = s.text(8);
  j.output_dir = s.text(9);
  j.params = s.text(10);
  j.progress_done = s.integer(11);
  j.progress_total = s.integer(12);
  return j;
}

bool job_exists(sqlite3* db, int64_t id) {
  Stmt s(db, "SELECT 1 FROM jobs WHERE id = ?1");
  s.bind(1, id);
  return s.step();
}

void insert_event(sqlite3* db, int64_t id, int64_t at_ms, const std::optional<std::string>& from,
                  const std::string& to, const std::string& reason) {
  Stmt s(db,
         "INSERT INTO events (job_id, at_ms, from_state, to_state, reason) "
         "VALUES (?1, ?2, ?3, ?4, ?5)");
  s.bind(1, id).bind(2, at_ms).bind(3, from).bind(4, to).bind(5, reason);
  s.run();
}

}  // namespace

Store::Store(const std::filesystem::path& db_file) {
  const std::string path = db_file.string();
  if (db_file.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(db_file.parent_path(), ec);
    if (ec) {
      throw StoreError("store " + path + ": cannot create folder " +
                       db_file.parent_path().string() + ": " + ec.message());
    }
  }
  int rc = sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE,
                           nullptr);
  if (rc != SQLITE_OK) {
    std::string msg = db_ ? sqlite3_errmsg(db_) : sqlite3_errstr(rc);
    sqlite3_close(db_);
    db_ = nullptr;
    throw StoreError("store " + path + ": cannot open: " + msg);
  }
  try {
    sqlite3_extended_result_codes(db_, 1);
    sqlite3_busy_timeout(db_, 5000);
    // Refuse a newer file before touching it (switching to WAL would rewrite its header).
    int found = read_user_version(db_);
    if (found > latest_schema_version()) {
      fail(db_, "database schema version " + std::to_string(found) +
                    " is newer than this atelier supports (version " +
                    std::to_string(latest_schema_version()) +
                    "); refusing to open it (upgrade atelier or use another store path)");
    }
    {
      Stmt s(db_, "PRAGMA journal_mode = WAL");
      std::string mode = s.step() ? s.text(0) : std::string();
      if (mode != "wal") {
        fail(db_, "cannot switch to WAL journal mode (SQLite kept '" + mode +
                      "'; is the folder on a network file system?)");
      }
    }
    exec("PRAGMA synchronous = NORMAL");
    exec("PRAGMA foreign_keys = ON");
    migrate();
  } catch (...) {
    sqlite3_close(db_);
    db_ = nullptr;
    throw;
  }
}

Store::~Store() {
  // Every statement is finalized by its scope, so close cannot be left pending.
  sqlite3_close(db_);
}

void Store::exec(const char* sql) { exec_sql(db_, sql, std::string("running \"") + sql + "\""); }

void Store::migrate() {
  const auto& steps = schema_migrations();
  for (size_t i = 0; i < steps.size(); ++i) {
    if (steps[i].to_version != static_cast<int>(i) + 1) {
      fail(db_, "schema step list is out of order at step " + std::to_string(i + 1));
    }
  }
  const int latest = latest_schema_version();
  // One step per transaction; the version is re-read under the write lock so two processes
  // opening the same file never apply a step twice.
  for (;;) {
    Transaction tx(db_);
    const int version = read_user_version(db_);
    if (version > latest) {
      fail(db_, "database schema version " + std::to_string(version) +
                    " is newer than this atelier supports (version " + std::to_string(latest) +
                    "); refusing to open it");
    }
    if (version == latest) {
      tx.commit();
      return;
    }
    const SchemaMigration& step = steps[static_cast<size_t>(version)];
    exec_sql(db_, step.sql,
             "migrating to schema version " + std::to_string(step.to_version) + " (" +
                 step.description + ")");
    // PRAGMA takes no bound parameters; the value is the code's own constant.
    const std::string bump = "PRAGMA user_version = " + std::to_string(step.to_version);
    exec(bump.c_str());
    tx.commit();
  }
}

int Store::schema_version() {
  std::lock_guard lock(mu_);
  return read_user_version(db_);
}

int64_t Store::reserve_id() {
  std::lock_guard lock(mu_);
  Transaction tx(db_);
  Stmt(db_, "UPDATE id_sequence SET last_id = last_id + 1 WHERE one = 1").run();
  int64_t id = 0;
  {
    Stmt s(db_, "SELECT last_id FROM id_sequence WHERE one = 1");
    if (!s.step()) fail(db_, "the id_sequence table has no row");
    id = s.integer(0);
  }
  tx.commit();
  return id;
}

void Store::insert_job(const Job& job) {
  std::lock_guard lock(mu_);
  Transaction tx(db_);
  {
    Stmt s(db_, "SELECT last_id FROM id_sequence WHERE one = 1");
    if (!s.step()) fail(db_, "the id_sequence table has no row");
    if (job.id <= 0 || job.id > s.integer(0)) {
      fail(db_, "job id " + std::to_string(job.id) + " was never reserved (last reserved " +
                    std::to_string(s.integer(0)) + ")");
    }
  }
  if (job_exists(db_, job.id)) fail(db_, "job " + std::to_string(job.id) + " already exists");
  // Zero times mean "now", so callers need not stamp a new job themselves.
  const int64_t created = job.created_ms != 0 ? job.created_ms : now_ms();
  const int64_t updated = job.updated_ms != 0 ? job.updated_ms : created;
  {
    Stmt s(db_, std::string("INSERT INTO jobs (") + kJobColumns +
                    ") VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13)");
    s.bind(1, job.id).bind(2, job.kind).bind(3, job.name).bind(4, state_name(job.state));
    s.bind(5, job.reason).bind(6, job.device).bind(7, created).bind(8, updated);
    s.bind(9, job.work_dir).bind(10, job.output_dir).bind(11, job.params);
    s.bind(12, job.progress_done).bind(13, job.progress_total);
    s.run();
  }
  insert_event(db_, job.id, created, std::nullopt, state_name(job.state), job.reason);
  tx.commit();
}

bool Store::has_job(int64_t id) {
  std::lock_guard lock(mu_);
  return job_exists(db_, id);
}

void Store::transition(int64_t id, JobState to, const std::string& reason,
                       const std::optional<std::string>& output_dir,
                       const std::optional<std::string>& device) {
  std::lock_guard lock(mu_);
  Transaction tx(db_);
  JobState from;
  {
    Stmt s(db_, "SELECT state FROM jobs WHERE id = ?1");
    s.bind(1, id);
    if (!s.step()) fail(db_, "no job " + std::to_string(id));
    from = parse_state(db_, s.text(0), "job " + std::to_string(id));
  }
  if (!transition_allowed(from, to)) {
    fail(db_, "job " + std::to_string(id) + ": illegal state change " + state_name(from) +
                  " -> " + state_name(to));
  }
  const int64_t at = now_ms();
  {
    // COALESCE keeps the stored value when the optional field is not given (bound NULL).
    Stmt s(db_,
           "UPDATE jobs SET state = ?1, reason = ?2, updated_ms = ?3, "
           "output_dir = COALESCE(?4, output_dir), device = COALESCE(?5, device) "
           "WHERE id = ?6");
    s.bind(1, state_name(to)).bind(2, reason).bind(3, at).bind(4, output_dir).bind(5, device);
    s.bind(6, id);
    s.run();
  }
  insert_event(db_, id, at, state_name(from), state_name(to), reason);
  tx.commit();
}

void Store::note(int64_t id, const std::string& reason) {
  std::lock_guard lock(mu_);
  Transaction tx(db_);
  std::string state;
  {
    Stmt s(db_, "SELECT state FROM jobs WHERE id = ?1");
    s.bind(1, id);
    if (!s.step()) fail(db_, "no job " + std::to_string(id));
    state = s.text(0);
  }
  const int64_t at = now_ms();
  {
    Stmt s(db_, "UPDATE jobs SET reason = ?1, updated_ms = ?2 WHERE id = ?3");
    s.bind(1, reason).bind(2, at).bind(3, id);
    s.run();
  }
  insert_event(db_, id, at, state, state, reason);
  tx.commit();
}

void Store::set_progress(int64_t id, int64_t done, int64_t total) {
  std::lock_guard lock(mu_);
  if (done < 0 || total < 0) {
    fail(db_, "job " + std::to_string(id) + ": negative progress " + std::to_string(done) + "/" +
                  std::to_string(total));
  }
  Stmt s(db_, "UPDATE jobs SET progress_done = ?1, progress_total = ?2 WHERE id = ?3");
  s.bind(1, done).bind(2, total).bind(3, id);
  s.run();
  if (sqlite3_changes(db_) == 0) fail(db_, "no job " + std::to_string(id));
}

void Store::set_progress(int64_t id, int64_t done, int64_t total, const std::string& reason) {
  set_progress(id, done, total);
  std::lock_guard lock(mu_);
  Stmt s(db_, "UPDATE jobs SET reason = ?1 WHERE id = ?2");
  s.bind(1, reason).bind(2, id);
  s.run();
}

std::optional<Job> Store::get(int64_t id) {
  std::lock_guard lock(mu_);
  Stmt s(db_, std::string("SELECT ") + kJobColumns + " FROM jobs WHERE id = ?1");
  s.bind(1, id);
  if (!s.step()) return std::nullopt;
  return read_job(db_, s);
}

namespace {

// " WHERE ..." for a filter's state (?1) and kind (?2); the SQL text varies only by which
// constant clauses are present, values are bound.
std::string filter_clause(const JobFilter& filter) {
  if (filter.state && filter.kind) return " WHERE state = ?1 AND kind = ?2";
  if (filter.state) return " WHERE state = ?1";
  if (filter.kind) return " WHERE kind = ?2";
  return "";
}

void bind_filter(Stmt& s, const JobFilter& filter) {
  if (filter.state) s.bind(1, state_name(*filter.state));
  if (filter.kind) s.bind(2, *filter.kind);
}

}  // namespace

std::vector<Job> Store::list(const JobFilter& filter) {
  std::lock_guard lock(mu_);
  Stmt s(db_, std::string("SELECT ") + kJobColumns + " FROM jobs" + filter_clause(filter) +
                  " ORDER BY id DESC LIMIT ?3 OFFSET ?4");
  bind_filter(s, filter);
  s.bind(3, filter.limit < 0 ? int64_t{-1} : filter.limit);  // SQLite: LIMIT -1 is no limit
  s.bind(4, std::max<int64_t>(0, filter.offset));
  std::vector<Job> jobs;
  while (s.step()) jobs.push_back(read_job(db_, s));
  return jobs;
}

int64_t Store::count(const JobFilter& filter) {
  std::lock_guard lock(mu_);
  Stmt s(db_, "SELECT COUNT(*) FROM jobs" + filter_clause(filter));
  bind_filter(s, filter);
  return s.step() ? s.integer(0) : 0;
}

std::vector<JobEvent> Store::history(int64_t id) {
  std::lock_guard lock(mu_);
  Stmt s(db_,
         "SELECT job_id, at_ms, from_state, to_state, reason FROM events "
         "WHERE job_id = ?1 ORDER BY id");
  s.bind(1, id);
  std::vector<JobEvent> events;
  while (s.step()) {
    JobEvent e;
    e.job_id = s.integer(0);
    e.at_ms = s.integer(1);
    e.from = s.is_null(2) ? std::string() : s.text(2);
    e.to = s.text(3);
    e.reason = s.text(4);
    events.push_back(std::move(e));
  }
  return events;
}

std::map<JobState, int64_t> Store::counts() {
  std::lock_guard lock(mu_);
  std::map<JobState, int64_t> result;
  for (JobState st : {JobState::queued, JobState::converting, JobState::ready, JobState::running,
                      JobState::completed, JobState::failed, JobState::canceled,
                      JobState::interrupted}) {
    result[st] = 0;
  }
  Stmt s(db_, "SELECT state, COUNT(*) FROM jobs GROUP BY state");
  while (s.step()) result[parse_state(db_, s.text(0), "a job row")] = s.integer(1);
  return result;
}

// Retention. The finished states as an SQL list of literals: the code's own state names.
namespace {
std::string finished_states_sql() {
  std::string list;
  for (JobState s : {JobState::queued, JobState::converting, JobState::ready, JobState::running,
                     JobState::completed, JobState::failed, JobState::canceled, JobState::interrupted})
    if (is_finished(s)) list += (list.empty() ? "'" : ", '") + state_name(s) + "'";
  return "(" + list + ")";
}
}  // namespace

std::vector<FinishedJob> Store::finished_jobs() {
  std::lock_guard lock(mu_);
  Stmt s(db_, "SELECT id, updated_ms FROM jobs WHERE state IN " + finished_states_sql() + " ORDER BY id");
  std::vector<FinishedJob> out;
  while (s.step()) out.push_back({s.integer(0), s.integer(1)});
  return out;
}

std::vector<int64_t> Store::purge(const std::vector<int64_t>& ids) {
  std::lock_guard lock(mu_);
  Transaction tx(db_);
  std::vector<int64_t> deleted;
  const std::string finished = finished_states_sql();
  for (int64_t id : ids) {
    std::string output_dir;
    {
      // Checked again here, under the write lock: a job retried since it was chosen stays.
      Stmt s(db_, "SELECT output_dir FROM jobs WHERE id = ?1 AND state IN " + finished);
      s.bind(1, id);
      if (!s.step()) continue;
      output_dir = s.text(0);
    }
    if (!output_dir.empty()) {
      Stmt s(db_, "INSERT OR REPLACE INTO purged_folders (job_id, path) VALUES (?1, ?2)");
      s.bind(1, id).bind(2, output_dir);
      s.run();
    }
    Stmt(db_, "DELETE FROM events WHERE job_id = ?1").bind(1, id).run();
    Stmt(db_, "DELETE FROM jobs WHERE id = ?1").bind(1, id).run();
    deleted.push_back(id);
  }
  tx.commit();
  std::sort(deleted.begin(), deleted.end());
  return deleted;
}

std::vector<PurgedFolder> Store::purged_folders() {
  std::lock_guard lock(mu_);
  Stmt s(db_, "SELECT job_id, path FROM purged_folders ORDER BY job_id");
  std::vector<PurgedFolder> out;
  while (s.step()) out.push_back({s.integer(0), s.text(1)});
  return out;
}

void Store::forget_purged_folder(int64_t job_id) {
  std::lock_guard lock(mu_);
  Stmt(db_, "DELETE FROM purged_folders WHERE job_id = ?1").bind(1, job_id).run();
}

int64_t Store::add_console_line(const ConsoleLine& l) {
  std::lock_guard lock(mu_);
  Stmt(db_, "INSERT INTO console_log (at_ms, device, uid, line, reply) VALUES (?1, ?2, ?3, ?4, ?5)")
      .bind(1, l.at_ms ? l.at_ms : now_ms())
      .bind(2, l.device)
      .bind(3, l.uid)
      .bind(4, l.line)
      .bind(5, l.reply)
      .run();
  return sqlite3_last_insert_rowid(db_);
}

std::vector<ConsoleLine> Store::console_lines(const std::string& device, int64_t limit) {
  std::lock_guard lock(mu_);
  // Newest `limit` by id, then turned oldest first as a terminal shows them.
  Stmt s(db_, "SELECT id, at_ms, device, uid, line, reply FROM console_log "
              "WHERE (?1 = '' OR device = ?1) ORDER BY id DESC LIMIT ?2");
  s.bind(1, device).bind(2, limit);
  std::vector<ConsoleLine> out;
  while (s.step()) out.push_back({s.integer(0), s.integer(1), s.text(2), s.integer(3), s.text(4), s.text(5)});
  std::reverse(out.begin(), out.end());
  return out;
}

}  // namespace atelier
