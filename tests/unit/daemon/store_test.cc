// Tests for the job store (daemon/store.h): schema and migrations, ids, the state
// machine, history, listing, counts, progress, threads and persistence.
#include "daemon/store.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <thread>

#include "daemon/store_schema.h"
#include "tests/unit/daemon/store_fixture.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using test::kAllowed;
using test::kAllStates;
using test::S;
using test::StoreTest;

// The version-1 schema exactly as released, so an old database can be built by hand. This
// copy is deliberately separate from store_schema.cc: if someone edits step 1 there, old
// databases in the field still look like this.
constexpr const char* kV1Sql = R"sql(
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

// A second, independent connection for looking at the file from outside the Store.
class RawDb {
 public:
  explicit RawDb(const fs::path& path) {
    if (sqlite3_open(path.c_str(), &db_) != SQLITE_OK) {
      ADD_FAILURE() << "cannot open " << path << ": " << sqlite3_errmsg(db_);
    }
  }
  ~RawDb() { sqlite3_close(db_); }
  void exec(const std::string& sql) {
    char* err = nullptr;
    if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &err) != SQLITE_OK) {
      ADD_FAILURE() << sql << ": " << (err ? err : "?");
    }
    sqlite3_free(err);
  }
  // The first column of the first row as text ("" when there is no row).
  std::string text(const std::string& sql) {
    sqlite3_stmt* st = nullptr;
    std::string out;
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &st, nullptr) != SQLITE_OK) {
      ADD_FAILURE() << sql << ": " << sqlite3_errmsg(db_);
      return out;
    }
    if (sqlite3_step(st) == SQLITE_ROW && sqlite3_column_text(st, 0)) {
      out = reinterpret_cast<const char*>(sqlite3_column_text(st, 0));
    }
    sqlite3_finalize(st);
    return out;
  }
  int64_t integer(const std::string& sql) { return std::stoll(text(sql)); }

 private:
  sqlite3* db_ = nullptr;
};

void expect_same_job(const Job& a, const Job& b) {
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.kind, b.kind);
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.state, b.state);
  EXPECT_EQ(a.reason, b.reason);
  EXPECT_EQ(a.device, b.device);
  EXPECT_EQ(a.created_ms, b.created_ms);
  EXPECT_EQ(a.updated_ms, b.updated_ms);
  EXPECT_EQ(a.work_dir, b.work_dir);
  EXPECT_EQ(a.output_dir, b.output_dir);
  EXPECT_EQ(a.params, b.params);
  EXPECT_EQ(a.progress_done, b.progress_done);
  EXPECT_EQ(a.progress_total, b.progress_total);
}

void expect_same_history(const std::vector<JobEvent>& a, const std::vector<JobEvent>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].job_id, b[i].job_id);
    EXPECT_EQ(a[i].at_ms, b[i].at_ms);
    EXPECT_EQ(a[i].from, b[i].from);
    EXPECT_EQ(a[i].to, b[i].to);
    EXPECT_EQ(a[i].reason, b[i].reason);
  }
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const StoreError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a StoreError";
  return "";
}

// ---- schema ---------------------------------------------------------------------------

TEST_F(StoreTest, FreshDatabaseIsWalAtLatestVersion) {
  Store store(db_path());
  EXPECT_EQ(latest_schema_version(), 4);
  EXPECT_EQ(store.schema_version(), latest_schema_version());

  RawDb raw(db_path());
  EXPECT_EQ(raw.text("PRAGMA journal_mode"), "wal");
  EXPECT_EQ(raw.integer("PRAGMA user_version"), latest_schema_version());
  for (const char* table : {"jobs", "events", "id_sequence", "purged_folders", "console_log"}) {
    EXPECT_EQ(raw.integer(std::string("SELECT COUNT(*) FROM sqlite_master WHERE type = 'table' "
                                      "AND name = '") + table + "'"), 1) << table;
  }
  for (const char* index : {"events_by_job", "jobs_by_state", "jobs_by_kind"}) {
    EXPECT_EQ(raw.integer(std::string("SELECT COUNT(*) FROM sqlite_master WHERE type = 'index' "
                                      "AND name = '") + index + "'"), 1) << index;
  }
}

TEST_F(StoreTest, MigratesVersionOneDatabaseKeepingItsRows) {
  fs::create_directories(db_path().parent_path());
  {
    RawDb raw(db_path());
    raw.exec(kV1Sql);
    raw.exec("PRAGMA user_version = 1");
    raw.exec("UPDATE id_sequence SET last_id = 5");
    raw.exec("INSERT INTO jobs (id, kind, name, state, reason, device, created_ms, updated_ms, "
             "work_dir, output_dir, params, progress_done, progress_total) VALUES "
             "(3, 'knit', 'old.png', 'running', 'knitting', 'knitter', 1000, 2000, "
             "'/spool/work/3', '', 'width = 80', 12, 90)");
    raw.exec("INSERT INTO events (job_id, at_ms, from_state, to_state, reason) VALUES "
             "(3, 1000, NULL, 'queued', 'dropped'), (3, 1500, 'queued', 'converting', 'picked up'),"
             "(3, 1800, 'converting', 'ready', 'converted'), (3, 2000, 'ready', 'running', 'knitting')");
  }
  Store store(db_path());
  EXPECT_EQ(store.schema_version(), latest_schema_version());

  auto job = store.get(3);
  ASSERT_TRUE(job.has_value());
  EXPECT_EQ(job->kind, "knit");
  EXPECT_EQ(job->name, "old.png");
  EXPECT_EQ(job->state, S::running);
  EXPECT_EQ(job->reason, "knitting");
  EXPECT_EQ(job->device, "knitter");
  EXPECT_EQ(job->created_ms, 1000);
  EXPECT_EQ(job->updated_ms, 2000);
  EXPECT_EQ(job->work_dir, "/spool/work/3");
  EXPECT_EQ(job->params, "width = 80");
  EXPECT_EQ(job->progress_done, 12);
  EXPECT_EQ(job->progress_total, 90);
  auto events = store.history(3);
  ASSERT_EQ(events.size(), 4u);
  EXPECT_EQ(events[0].from, "");
  EXPECT_EQ(events[3].reason, "knitting");

  // The id sequence carries over (ids 4 and 5 were reserved before the upgrade).
  EXPECT_EQ(store.reserve_id(), 6);
  store.transition(3, S::interrupted, "daemon restarted while running");
  EXPECT_EQ(store.history(3).size(), 5u);

  RawDb raw(db_path());
  EXPECT_EQ(raw.integer("PRAGMA user_version"), latest_schema_version());
  EXPECT_EQ(raw.text("PRAGMA journal_mode"), "wal");
  EXPECT_EQ(raw.integer("SELECT COUNT(*) FROM sqlite_master WHERE type = 'index' AND name IN "
                        "('jobs_by_state', 'jobs_by_kind')"), 2);
}

TEST_F(StoreTest, FailedMigrationStepRollsBackWholeAndNamesTheStep) {
  fs::create_directories(db_path().parent_path());
  {
    RawDb raw(db_path());
    raw.exec(kV1Sql);
    raw.exec("PRAGMA user_version = 1");
    raw.exec("INSERT INTO jobs (id, kind, name, state, created_ms, updated_ms) "
             "VALUES (1, 'knit', 'a.png', 'queued', 1, 1)");
    // An object squatting on a name step 2 creates makes that step fail halfway.
    raw.exec("CREATE TABLE jobs_by_kind (x INTEGER)");
  }
  std::string msg = error_of([&] { Store store(db_path()); });
  EXPECT_NE(msg.find(db_path().string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("schema version 2"), std::string::npos) << msg;
  EXPECT_NE(msg.find("jobs_by_kind"), std::string::npos) << msg;  // SQLite's own message

  RawDb raw(db_path());
  EXPECT_EQ(raw.integer("PRAGMA user_version"), 1);
  // The step's first statement ran before the failure and was rolled back with it.
  EXPECT_EQ(raw.integer("SELECT COUNT(*) FROM sqlite_master WHERE name = 'jobs_by_state'"), 0);
  EXPECT_EQ(raw.integer("SELECT COUNT(*) FROM jobs"), 1);
}

TEST_F(StoreTest, RefusesDatabaseFromNewerVersionAndLeavesItAlone) {
  fs::create_directories(db_path().parent_path());
  const int future = latest_schema_version() + 3;
  {
    RawDb raw(db_path());
    raw.exec("CREATE TABLE jobs (id INTEGER PRIMARY KEY, something_new TEXT)");
    raw.exec("PRAGMA user_version = " + std::to_string(future));
  }
  std::string msg = error_of([&] { Store store(db_path()); });
  EXPECT_NE(msg.find(db_path().string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("version " + std::to_string(future)), std::string::npos) << msg;
  EXPECT_NE(msg.find("version " + std::to_string(latest_schema_version())), std::string::npos)
      << msg;

  RawDb raw(db_path());
  EXPECT_EQ(raw.integer("PRAGMA user_version"), future);
  EXPECT_EQ(raw.text("PRAGMA journal_mode"), "delete");  // not switched to WAL
  EXPECT_EQ(raw.integer("SELECT COUNT(*) FROM sqlite_master WHERE name = 'events'"), 0);
}

TEST_F(StoreTest, NonDatabaseFileIsRefusedNamingFileAndSqliteError) {
  fs::create_directories(db_path().parent_path());
  std::ofstream(db_path()) << "this is a text file that someone put where the store should be, "
                              "long enough to fill a database header and then some more.\n";
  std::string msg = error_of([&] { Store store(db_path()); });
  EXPECT_NE(msg.find(db_path().string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("not a database"), std::string::npos) << msg;
}

TEST_F(StoreTest, UncreatableFolderIsAnErrorNamingThePath) {
  std::ofstream(dir_ / "blocker") << "a file, not a folder";
  fs::path path = dir_ / "blocker" / "jobs.sqlite";
  std::string msg = error_of([&] { Store store(path); });
  EXPECT_NE(msg.find(path.string()), std::string::npos) << msg;
}

// ---- ids and jobs ---------------------------------------------------------------------

TEST_F(StoreTest, ReservedIdsIncreaseAndAreNeverReusedAcrossReopen) {
  int64_t a, b, c;
  {
    Store store(db_path());
    a = store.reserve_id();
    b = store.reserve_id();
    c = store.reserve_id();
    EXPECT_LT(a, b);
    EXPECT_LT(b, c);
    store.insert_job(make_job(b, "knit", "b.png"));
    // a and c are never inserted, as after a crash between reserve and insert.
  }
  Store store(db_path());
  int64_t d = store.reserve_id();
  EXPECT_GT(d, c);
  EXPECT_FALSE(store.has_job(a));
  EXPECT_TRUE(store.has_job(b));
  EXPECT_FALSE(store.has_job(c));
}

TEST_F(StoreTest, InsertRefusesUnreservedAndDuplicateIds) {
  Store store(db_path());
  int64_t id = add_job(store);
  std::string dup = error_of([&] { store.insert_job(make_job(id, "knit", "again.png")); });
  EXPECT_NE(dup.find("job " + std::to_string(id)), std::string::npos) << dup;
  EXPECT_NE(dup.find(db_path().string()), std::string::npos) << dup;
  EXPECT_EQ(store.get(id)->name, "cat.jpg");
  EXPECT_EQ(store.history(id).size(), 1u);

  std::string unreserved = error_of([&] { store.insert_job(make_job(id + 50, "knit", "x.png")); });
  EXPECT_NE(unreserved.find(std::to_string(id + 50)), std::string::npos) << unreserved;
  EXPECT_THROW(store.insert_job(make_job(0, "knit", "zero.png")), StoreError);
  EXPECT_FALSE(store.has_job(id + 50));
  // The refused ids did not move the sequence backwards or forwards.
  EXPECT_EQ(store.reserve_id(), id + 1);
}

TEST_F(StoreTest, InsertAndGetRoundTripEveryField) {
  Store store(db_path());
  Job job;
  job.id = store.reserve_id();
  job.kind = "embroidery";
  job.name = "O'Brien \"cat\"; DROP TABLE jobs; -- é.jpg";
  job.state = S::queued;
  job.reason = "dropped in incoming/embroidery";
  job.device = "embroidery";
  job.created_ms = 1700000000123;
  job.updated_ms = 1700000000456;
  job.work_dir = "/var/spool/atelier/work/7";
  job.output_dir = "/var/spool/atelier/done/7";
  job.params = "colors = 6\n[satin]\nmax_width_mm = 7.5\n";
  job.progress_done = 3;
  job.progress_total = 17;
  store.insert_job(job);

  EXPECT_TRUE(store.has_job(job.id));
  auto got = store.get(job.id);
  ASSERT_TRUE(got.has_value());
  expect_same_job(*got, job);
  EXPECT_FALSE(store.get(job.id + 1).has_value());
  EXPECT_FALSE(store.has_job(job.id + 1));

  auto events = store.history(job.id);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].job_id, job.id);
  EXPECT_EQ(events[0].from, "");
  EXPECT_EQ(events[0].to, "queued");
  EXPECT_EQ(events[0].reason, job.reason);
  EXPECT_EQ(events[0].at_ms, job.created_ms);

  RawDb raw(db_path());
  EXPECT_EQ(raw.integer("SELECT COUNT(*) FROM jobs"), 1);
}

TEST_F(StoreTest, ZeroTimesAreStampedWithNow) {
  Store store(db_path());
  int64_t before = now_ms();
  int64_t id = add_job(store);
  int64_t after = now_ms();
  auto job = store.get(id);
  ASSERT_TRUE(job.has_value());
  EXPECT_GE(job->created_ms, before);
  EXPECT_LE(job->created_ms, after);
  EXPECT_EQ(job->updated_ms, job->created_ms);
}

// ---- transitions ----------------------------------------------------------------------

TEST_F(StoreTest, EveryAllowedEdgeWorks) {
  Store store(db_path());
  for (const auto& [from, to] : kAllowed) {
    const std::string edge = state_name(from) + " -> " + state_name(to);
    int64_t id = add_job(store);
    drive_to(store, id, from);
    ASSERT_EQ(store.get(id)->state, from) << edge;
    size_t before = store.history(id).size();
    int64_t t0 = now_ms();
    store.transition(id, to, "because " + edge);

    auto job = store.get(id);
    EXPECT_EQ(job->state, to) << edge;
    EXPECT_EQ(job->reason, "because " + edge);
    EXPECT_GE(job->updated_ms, t0);
    auto events = store.history(id);
    ASSERT_EQ(events.size(), before + 1) << edge;
    EXPECT_EQ(events.back().from, state_name(from));
    EXPECT_EQ(events.back().to, state_name(to));
    EXPECT_EQ(events.back().reason, "because " + edge);
    EXPECT_EQ(events.back().at_ms, job->updated_ms);
  }
}

TEST_F(StoreTest, IllegalEdgesThrowNamingJobAndStatesAndChangeNothing) {
  Store store(db_path());
  int illegal = 0;
  for (JobState from : kAllStates) {
    for (JobState to : kAllStates) {
      if (kAllowed.count({from, to})) continue;
      ++illegal;
      const std::string edge = state_name(from) + " -> " + state_name(to);
      int64_t id = add_job(store);
      drive_to(store, id, from);
      store.set_progress(id, 5, 10);
      Job before = *store.get(id);
      auto events_before = store.history(id);

      std::string msg = error_of([&] {
        store.transition(id, to, "should not happen", std::string("/out"), std::string("dev"));
      });
      EXPECT_NE(msg.find("job " + std::to_string(id)), std::string::npos) << edge << ": " << msg;
      EXPECT_NE(msg.find(state_name(from) + " -> " + state_name(to)), std::string::npos)
          << edge << ": " << msg;
      expect_same_job(*store.get(id), before);
      expect_same_history(store.history(id), events_before);
    }
  }
  EXPECT_EQ(illegal, 64 - 19);
}

TEST_F(StoreTest, TransitionOfUnknownJobThrows) {
  Store store(db_path());
  std::string msg = error_of([&] { store.transition(42, S::converting, "x"); });
  EXPECT_NE(msg.find("42"), std::string::npos) << msg;
  EXPECT_TRUE(store.history(42).empty());
}

TEST_F(StoreTest, OutputDirAndDeviceAreSetWhenGivenAndKeptOtherwise) {
  Store store(db_path());
  int64_t id = add_job(store);
  store.transition(id, S::converting, "picked up");
  store.transition(id, S::ready, "converted", std::string("/spool/done/1"), std::string("laser"));
  store.transition(id, S::running, "armed by operator");
  auto job = store.get(id);
  EXPECT_EQ(job->output_dir, "/spool/done/1");
  EXPECT_EQ(job->device, "laser");
  store.transition(id, S::failed, "alarm 1: hard limit", std::string("/spool/failed/1"),
                   std::string(""));
  job = store.get(id);
  EXPECT_EQ(job->output_dir, "/spool/failed/1");
  EXPECT_EQ(job->device, "");  // an explicit empty value clears it
}

// ---- history, list, counts, progress ---------------------------------------------------

TEST_F(StoreTest, HistoryIsInOrderWithReasons) {
  Store store(db_path());
  int64_t other = add_job(store, "laser", "other.svg");
  int64_t id = add_job(store, "knit", "fish.jpg");
  const std::vector<std::pair<JobState, std::string>> steps = {
      {S::converting, "picked up"},
      {S::failed, "decode error: truncated JPEG"},
      {S::queued, "retry by operator"},
      {S::converting, "picked up again"},
      {S::ready, "outputs written"},
      {S::running, "knitter free"},
      {S::interrupted, "daemon restarted while running"},
      {S::running, "resumed from row 40"},
      {S::completed, "all 120 rows knitted"},
  };
  store.transition(other, S::canceled, "canceled by user");  // interleaved, must not mix in
  for (const auto& [to, why] : steps) store.transition(id, to, why);

  auto events = store.history(id);
  ASSERT_EQ(events.size(), steps.size() + 1);
  EXPECT_EQ(events[0].from, "");
  EXPECT_EQ(events[0].to, "queued");
  std::string prev = "queued";
  for (size_t i = 0; i < steps.size(); ++i) {
    const JobEvent& e = events[i + 1];
    EXPECT_EQ(e.job_id, id);
    EXPECT_EQ(e.from, prev) << i;
    EXPECT_EQ(e.to, state_name(steps[i].first)) << i;
    EXPECT_EQ(e.reason, steps[i].second) << i;
    EXPECT_GE(e.at_ms, events[i].at_ms) << i;
    prev = e.to;
  }
  EXPECT_EQ(store.history(other).size(), 2u);
  EXPECT_TRUE(store.history(9999).empty());
}

TEST_F(StoreTest, ListFiltersByStateAndKindNewestFirst) {
  Store store(db_path());
  int64_t k1 = add_job(store, "knit", "k1.png");
  int64_t l1 = add_job(store, "lace", "l1.toml");
  int64_t k2 = add_job(store, "knit", "k2.png");
  int64_t s1 = add_job(store, "sketch", "s1.png");
  int64_t k3 = add_job(store, "knit", "k3.png");
  int64_t l2 = add_job(store, "lace", "l2.toml");
  store.transition(k2, S::converting, "picked up");
  store.transition(s1, S::converting, "picked up");
  store.transition(l2, S::canceled, "canceled by user");

  auto ids = [](const std::vector<Job>& jobs) {
    std::vector<int64_t> out;
    for (const Job& j : jobs) out.push_back(j.id);
    return out;
  };
  using V = std::vector<int64_t>;
  // Designated initializers would warn under -Wextra for the members left out.
  auto filter = [](std::optional<JobState> state, std::optional<std::string> kind,
                   int limit = 1000) {
    JobFilter f;
    f.state = state;
    f.kind = std::move(kind);
    f.limit = limit;
    return f;
  };
  EXPECT_EQ(ids(store.list({})), (V{l2, k3, s1, k2, l1, k1}));
  EXPECT_EQ(ids(store.list(filter(S::queued, std::nullopt))), (V{k3, l1, k1}));
  EXPECT_EQ(ids(store.list(filter(std::nullopt, "knit"))), (V{k3, k2, k1}));
  EXPECT_EQ(ids(store.list(filter(S::converting, "knit"))), (V{k2}));
  EXPECT_EQ(ids(store.list(filter(S::queued, "knit", 1))), (V{k3}));
  EXPECT_EQ(ids(store.list(filter(std::nullopt, std::nullopt, 2))), (V{l2, k3}));
  EXPECT_TRUE(store.list(filter(S::running, std::nullopt)).empty());
  EXPECT_TRUE(store.list(filter(std::nullopt, "parquetry")).empty());
  // Rows come back whole, not just ids.
  auto lace = store.list(filter(S::canceled, std::nullopt));
  ASSERT_EQ(lace.size(), 1u);
  EXPECT_EQ(lace[0].name, "l2.toml");
  EXPECT_EQ(lace[0].reason, "canceled by user");
}

TEST_F(StoreTest, CountIsEveryMatchingJobWhateverTheLimitAndANegativeLimitListsAll) {
  Store store(db_path());
  for (int i = 0; i < 1003; ++i) add_job(store, i % 5 == 0 ? "lace" : "knit", "j" + std::to_string(i) + ".png");
  JobFilter page;  // the default page: the 1000 newest
  EXPECT_EQ(store.list(page).size(), 1000u);
  EXPECT_EQ(store.count(page), 1003);
  JobFilter every;
  every.limit = -1;
  EXPECT_EQ(store.list(every).size(), 1003u);
  JobFilter lace;
  lace.kind = "lace";
  lace.limit = 3;
  EXPECT_EQ(store.list(lace).size(), 3u);
  EXPECT_EQ(store.count(lace), 201);
  lace.state = JobState::failed;
  EXPECT_EQ(store.count(lace), 0);
}

TEST_F(StoreTest, CountsIncludeEveryStateEvenZero) {
  Store store(db_path());
  auto empty = store.counts();
  EXPECT_EQ(empty.size(), kAllStates.size());
  for (JobState s : kAllStates) EXPECT_EQ(empty.at(s), 0) << state_name(s);

  add_job(store);
  add_job(store);
  int64_t c = add_job(store);
  int64_t d = add_job(store);
  store.transition(c, S::converting, "picked up");
  store.transition(d, S::canceled, "canceled by user");
  auto counts = store.counts();
  EXPECT_EQ(counts.size(), kAllStates.size());
  EXPECT_EQ(counts.at(S::queued), 2);
  EXPECT_EQ(counts.at(S::converting), 1);
  EXPECT_EQ(counts.at(S::canceled), 1);
  for (JobState s : {S::ready, S::running, S::completed, S::failed, S::interrupted}) {
    EXPECT_EQ(counts.at(s), 0) << state_name(s);
  }
}

TEST_F(StoreTest, ProgressUpdatesWithoutEventsOrStateChange) {
  Store store(db_path());
  int64_t id = add_job(store);
  store.transition(id, S::converting, "picked up");
  store.set_progress(id, 40, 120);
  auto job = store.get(id);
  EXPECT_EQ(job->progress_done, 40);
  EXPECT_EQ(job->progress_total, 120);
  EXPECT_EQ(job->state, S::converting);
  store.set_progress(id, 120, 120);
  EXPECT_EQ(store.get(id)->progress_done, 120);
  EXPECT_EQ(store.history(id).size(), 2u);

  std::string msg = error_of([&] { store.set_progress(id + 7, 1, 2); });
  EXPECT_NE(msg.find(std::to_string(id + 7)), std::string::npos) << msg;
  EXPECT_THROW(store.set_progress(id, -1, 120), StoreError);
  EXPECT_EQ(store.get(id)->progress_done, 120);
}

// ---- threads and persistence -----------------------------------------------------------

TEST_F(StoreTest, ConcurrentTransitionsFromFourThreadsAllLand) {
  Store store(db_path());
  constexpr int kThreads = 4;
  constexpr int kJobsPerThread = 25;
  const std::vector<JobState> walk = {S::converting, S::ready, S::running, S::completed};
  std::vector<std::vector<int64_t>> ids(kThreads);
  std::vector<std::string> errors(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      try {
        for (int i = 0; i < kJobsPerThread; ++i) {
          int64_t id = store.reserve_id();
          store.insert_job(make_job(id, "knit", "t" + std::to_string(t) + ".png"));
          ids[t].push_back(id);
        }
        for (JobState s : walk) {
          for (int64_t id : ids[t]) {
            store.transition(id, s, "thread " + std::to_string(t));
            store.set_progress(id, 1, 2);
          }
        }
      } catch (const std::exception& e) {
        errors[t] = e.what();
      }
    });
  }
  for (auto& th : threads) th.join();
  for (int t = 0; t < kThreads; ++t) EXPECT_EQ(errors[t], "") << "thread " << t;

  std::set<int64_t> unique;
  for (const auto& v : ids) unique.insert(v.begin(), v.end());
  EXPECT_EQ(unique.size(), static_cast<size_t>(kThreads * kJobsPerThread));
  EXPECT_EQ(store.counts().at(S::completed), kThreads * kJobsPerThread);
  for (int64_t id : unique) ASSERT_EQ(store.history(id).size(), walk.size() + 1) << id;
  RawDb raw(db_path());
  EXPECT_EQ(raw.integer("SELECT COUNT(*) FROM events"),
            static_cast<int64_t>(kThreads * kJobsPerThread * (walk.size() + 1)));
}

TEST_F(StoreTest, DataSurvivesCloseAndReopen) {
  Job saved;
  std::vector<JobEvent> saved_history;
  std::map<JobState, int64_t> saved_counts;
  int64_t last_id;
  {
    Store store(db_path());
    int64_t a = add_job(store, "sketch", "a.png");
    int64_t b = add_job(store, "cut", "b.svg");
    store.transition(a, S::converting, "picked up");
    store.transition(a, S::ready, "outputs written", std::string("/spool/done/1"),
                     std::string("laser"));
    store.set_progress(a, 10, 30);
    store.transition(b, S::canceled, "canceled by user");
    saved = *store.get(a);
    saved_history = store.history(a);
    saved_counts = store.counts();
    last_id = b;
  }
  Store store(db_path());
  EXPECT_EQ(store.schema_version(), latest_schema_version());
  expect_same_job(*store.get(saved.id), saved);
  expect_same_history(store.history(saved.id), saved_history);
  EXPECT_EQ(store.counts(), saved_counts);
  EXPECT_GT(store.reserve_id(), last_id);
  // The reopened store keeps working.
  store.transition(saved.id, S::running, "armed");
  EXPECT_EQ(store.get(saved.id)->state, S::running);
}

// Retention's part of the store: which finished jobs there are, and purging them.
TEST_F(StoreTest, FinishedJobsAreCompletedFailedAndCanceledWithTheirLastChange) {
  Store store(db_path());
  std::map<JobState, int64_t> id_in;
  for (JobState st : test::kAllStates) {
    id_in[st] = add_job(store);
    drive_to(store, id_in[st], st);
  }
  std::set<int64_t> finished;
  for (const FinishedJob& f : store.finished_jobs()) {
    finished.insert(f.id);
    EXPECT_EQ(f.finished_ms, store.get(f.id)->updated_ms) << f.id;
  }
  EXPECT_EQ(finished, (std::set<int64_t>{id_in[S::completed], id_in[S::failed], id_in[S::canceled]}));
  for (JobState st : test::kAllStates)
    EXPECT_EQ(is_finished(st), st == S::completed || st == S::failed || st == S::canceled) << state_name(st);
}

TEST_F(StoreTest, PurgeDeletesFinishedJobsWithTheirHistoryAndRecordsTheirFolders) {
  Store store(db_path());
  std::map<JobState, int64_t> id_in;
  for (JobState st : test::kAllStates) {
    id_in[st] = add_job(store);
    const std::vector<JobState> path = path_to(st);
    for (size_t i = 0; i < path.size(); ++i) {
      // The last step records an output folder, as JobService does when a job finishes.
      std::optional<std::string> folder;
      if (i + 1 == path.size()) folder = "/spool/done/" + std::to_string(id_in[st]);
      store.transition(id_in[st], path[i], "step", folder);
    }
  }
  std::vector<int64_t> every;
  for (const auto& [st, id] : id_in) every.push_back(id);
  every.push_back(9999);  // no such job: skipped

  const std::vector<int64_t> purged = store.purge(every);

  std::vector<int64_t> expected{id_in[S::completed], id_in[S::failed], id_in[S::canceled]};
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(purged, expected);
  for (JobState st : test::kAllStates) {
    const int64_t id = id_in[st];
    if (is_finished(st)) {
      EXPECT_FALSE(store.get(id)) << state_name(st) << " job is gone";
      EXPECT_TRUE(store.history(id).empty()) << state_name(st) << " job's history is gone";
    } else {
      ASSERT_TRUE(store.get(id)) << "an unfinished (" << state_name(st) << ") job is never purged";
      EXPECT_EQ(store.get(id)->state, st);
      EXPECT_FALSE(store.history(id).empty());
    }
  }
  RawDb raw(db_path());
  EXPECT_EQ(raw.integer("SELECT COUNT(*) FROM events WHERE job_id NOT IN (SELECT id FROM jobs)"), 0);
  std::vector<std::pair<int64_t, std::string>> folders;
  for (const PurgedFolder& f : store.purged_folders()) folders.emplace_back(f.job_id, f.path);
  std::vector<std::pair<int64_t, std::string>> want;
  for (int64_t id : expected) want.emplace_back(id, "/spool/done/" + std::to_string(id));
  EXPECT_EQ(folders, want);
  store.forget_purged_folder(expected[0]);
  EXPECT_EQ(store.purged_folders().size(), 2u);
  EXPECT_EQ(store.counts()[S::completed], 0);
}

TEST_F(StoreTest, ADatabaseMigratedFromVersionOneCanPurge) {
  fs::create_directories(db_path().parent_path());
  {
    RawDb raw(db_path());
    raw.exec(kV1Sql);
    raw.exec("PRAGMA user_version = 1");
  }
  {
    Store store(db_path());  // v1 -> latest
    const int64_t id = add_job(store);
    drive_to(store, id, S::completed);
    EXPECT_EQ(store.purge({id}), std::vector<int64_t>{id});
    EXPECT_TRUE(store.purged_folders().empty()) << "a job without an output folder records none";
  }
}

TEST_F(StoreTest, ConsoleLinesAreKeptPerDeviceAndTheLastOnesComeBackOldestFirst) {
  {
    Store store(db_path());
    store.add_console_line({0, 1000, "laser", 1000, "$X", "[MSG:Caution: Unlocked]\nok"});
    store.add_console_line({0, 2000, "other", 1000, "$H", "ok"});
    store.add_console_line({0, 3000, "laser", 0, "G0X5", "error:9"});
    store.add_console_line({0, 4000, "laser", 1000, "$$", "$0=10\nok"});
  }
  Store store(db_path());  // they survive a restart
  const auto last_two = store.console_lines("laser", 2);
  ASSERT_EQ(last_two.size(), 2u);
  EXPECT_EQ(last_two[0].line, "G0X5");
  EXPECT_EQ(last_two[0].reply, "error:9");
  EXPECT_EQ(last_two[0].uid, 0);
  EXPECT_EQ(last_two[1].line, "$$");
  EXPECT_EQ(last_two[1].at_ms, 4000);
  EXPECT_EQ(store.console_lines("laser", 10).size(), 3u);
  const auto all = store.console_lines("", 10);
  ASSERT_EQ(all.size(), 4u);
  EXPECT_EQ(all[1].device, "other");
  EXPECT_EQ(all[0].reply, "[MSG:Caution: Unlocked]\nok");
}

}  // namespace
}  // namespace atelier
