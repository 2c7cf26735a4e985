// Purging old finished jobs from the store and the spool (daemon/purge.h): which jobs and
// folders go, which stay, that nothing is followed out of the spool, that a cut-off pass is
// finished, and the worker's passes at start-up and each period on the clock seam.
#include "daemon/purge.h"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <linux/fs.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <atomic>
#include <condition_variable>
#include <filesystem>
#include <map>
#include <mutex>

#include "base/fake_clock.h"
#include "tests/e2e/daemon_harness.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using test::read_file;
using test::TempDir;
using test::write_file;

constexpr int64_t kDay = int64_t{24} * 60 * 60 * 1000;

class Purge : public ::testing::Test {
 protected:
  Purge() : store_(tmp_.path() / "jobs.sqlite"), layout_{tmp_.path() / "spool"} {
    fs::create_directories(layout_.done());
    fs::create_directories(layout_.failed());
    fs::create_directories(layout_.work());
  }

  // A job in `state` whose last change was `age_ms` ago, its files where JobService puts them:
  // done/<id> or failed/<id> once finished (recorded as output_dir), work/<id> before.
  int64_t job(JobState state, int64_t age_ms, bool in_failed = false) {
    Job j;
    j.id = store_.reserve_id();
    j.kind = "k";
    j.name = "in.png";
    j.state = state;
    j.created_ms = j.updated_ms = now_ms() - age_ms;
    fs::path folder = layout_.work(j.id);
    if (state == JobState::completed || state == JobState::failed || state == JobState::canceled ||
        state == JobState::ready || state == JobState::running || state == JobState::interrupted) {
      folder = in_failed ? layout_.failed(j.id) : layout_.done(j.id);
      j.output_dir = folder.string();
    }
    j.work_dir = layout_.work(j.id).string();
    fs::create_directories(folder);
    write_file(folder / j.name, "image");
    write_file(folder / "report.json", "{}");
    store_.insert_job(j);
    return j.id;
  }
  fs::path folder_of(int64_t id) {
    auto j = store_.get(id);
    return j && !j->output_dir.empty() ? fs::path(j->output_dir) : layout_.work(id);
  }

  TempDir tmp_;
  Store store_;
  SpoolLayout layout_;
};

TEST_F(Purge, OldFinishedJobsGoWithTheirFoldersAndEverythingElseStays) {
  const RetentionPolicy policy{.keep_days = 30, .keep_jobs = 0};
  const int64_t old_done = job(JobState::completed, 40 * kDay);
  const int64_t old_failed = job(JobState::failed, 40 * kDay, /*in_failed=*/true);
  const int64_t old_canceled = job(JobState::canceled, 40 * kDay, /*in_failed=*/true);
  const int64_t recent = job(JobState::completed, 2 * kDay);
  // Unfinished jobs, however old, are never purged.
  std::map<int64_t, JobState> unfinished;
  for (JobState st : {JobState::queued, JobState::converting, JobState::ready, JobState::running,
                      JobState::interrupted})
    unfinished[job(st, 400 * kDay)] = st;
  std::map<int64_t, fs::path> folders;
  for (int64_t id = 1; id <= old_done + 8; ++id)
    if (store_.get(id)) folders[id] = folder_of(id);

  const PurgeReport report = purge_finished_jobs(store_, layout_, policy, now_ms());

  EXPECT_EQ(report.jobs, (std::vector<int64_t>{old_done, old_failed, old_canceled}));
  EXPECT_EQ(report.folders_removed, 3);
  EXPECT_TRUE(report.problems.empty());
  for (int64_t id : {old_done, old_failed, old_canceled}) {
    EXPECT_FALSE(store_.get(id)) << id;
    EXPECT_FALSE(fs::exists(folders[id])) << folders[id];
  }
  EXPECT_TRUE(store_.get(recent));
  EXPECT_TRUE(fs::exists(folders[recent] / "report.json"));
  for (const auto& [id, st] : unfinished) {
    ASSERT_TRUE(store_.get(id)) << state_name(st) << " job was purged";
    EXPECT_EQ(store_.get(id)->state, st);
    EXPECT_EQ(read_file(folders[id] / "in.png"), "image") << state_name(st);
  }
  EXPECT_TRUE(store_.purged_folders().empty());
  EXPECT_EQ(purge_summary(report, policy),
            "retention: purged 3 finished jobs (" + std::to_string(old_done) + ", " + std::to_string(old_failed) +
                ", " + std::to_string(old_canceled) + ") and 3 output folders; [store] keep_days = 30, keep_jobs = 0");
  // A second pass finds nothing to do.
  const PurgeReport again = purge_finished_jobs(store_, layout_, policy, now_ms());
  EXPECT_TRUE(again.jobs.empty());
  EXPECT_EQ(purge_summary(again, policy), "");
}

TEST_F(Purge, KeepJobsKeepsTheMostRecentlyFinished) {
  std::vector<int64_t> ids;
  for (int i = 0; i < 5; ++i) ids.push_back(job(JobState::completed, (5 - i) * 1000));  // later = newer
  const int64_t queued = job(JobState::queued, 10000);
  const PurgeReport report = purge_finished_jobs(store_, layout_, {.keep_days = 0, .keep_jobs = 2}, now_ms());
  EXPECT_EQ(report.jobs, (std::vector<int64_t>{ids[0], ids[1], ids[2]}));
  EXPECT_TRUE(store_.get(ids[3]));
  EXPECT_TRUE(store_.get(ids[4]));
  EXPECT_TRUE(store_.get(queued)) << "keep_jobs counts finished jobs only";
  EXPECT_TRUE(fs::exists(layout_.done(ids[4])));
  EXPECT_FALSE(fs::exists(layout_.done(ids[0])));
}

TEST_F(Purge, ASymlinkInAnOutputFolderIsRemovedWithoutFollowingIt) {
  const fs::path outside = tmp_.path() / "outside";
  fs::create_directories(outside / "keep");
  write_file(outside / "precious.txt", "the workshop's");
  write_file(outside / "keep" / "inner.txt", "also");
  const int64_t id = job(JobState::failed, 40 * kDay, /*in_failed=*/true);
  // What a user dropped may be a folder kept in failed/<id>/, with links of their making.
  fs::create_directories(layout_.failed(id) / "dropped" / "sub");
  fs::create_directory_symlink(outside / "keep", layout_.failed(id) / "dropped" / "sub" / "link");
  fs::create_symlink(outside / "precious.txt", layout_.failed(id) / "precious.txt");

  const PurgeReport report = purge_finished_jobs(store_, layout_, {.keep_days = 30, .keep_jobs = 0}, now_ms());

  EXPECT_EQ(report.jobs, std::vector<int64_t>{id});
  EXPECT_TRUE(report.problems.empty()) << report.problems.front();
  EXPECT_FALSE(fs::exists(fs::symlink_status(layout_.failed(id))));
  EXPECT_EQ(read_file(outside / "precious.txt"), "the workshop's");
  EXPECT_EQ(read_file(outside / "keep" / "inner.txt"), "also");
}

TEST_F(Purge, AFolderRecordedOutsideTheJobsPlaceInTheSpoolIsLeftAlone) {
  const fs::path elsewhere = tmp_.path() / "elsewhere" / "7";
  fs::create_directories(elsewhere);
  write_file(elsewhere / "precious.txt", "keep");
  Job j;
  j.id = store_.reserve_id();
  j.kind = "k";
  j.name = "in.png";
  j.state = JobState::completed;
  j.created_ms = j.updated_ms = now_ms() - 40 * kDay;
  j.output_dir = elsewhere.string();  // e.g. a spool since moved, or a row edited by hand
  store_.insert_job(j);
  // Nor another job's folder, nor one reached through "..".
  Job k = j;
  k.id = store_.reserve_id();
  k.output_dir = (layout_.done() / ".." / "failed" / std::to_string(j.id) / "..").string();
  store_.insert_job(k);
  fs::create_directories(layout_.failed(j.id));

  const PurgeReport report = purge_finished_jobs(store_, layout_, {.keep_days = 30, .keep_jobs = 0}, now_ms());

  EXPECT_EQ(report.jobs, (std::vector<int64_t>{j.id, k.id}));
  EXPECT_EQ(report.folders_removed, 0);
  ASSERT_EQ(report.problems.size(), 2u);
  EXPECT_NE(report.problems[0].find(elsewhere.string() + ": not job " + std::to_string(j.id) + "'s folder"),
            std::string::npos)
      << report.problems[0];
  EXPECT_EQ(read_file(elsewhere / "precious.txt"), "keep");
  EXPECT_TRUE(fs::exists(layout_.failed(j.id)));
  EXPECT_TRUE(store_.purged_folders().empty()) << "not tried again";
}

TEST_F(Purge, AFolderLeftByACutOffPassIsRemovedByTheNext) {
  const int64_t id = job(JobState::completed, 40 * kDay);
  // The rows went and the folder was recorded, then the daemon died before removing it.
  ASSERT_EQ(store_.purge({id}), std::vector<int64_t>{id});
  ASSERT_TRUE(fs::exists(layout_.done(id)));
  const PurgeReport report = purge_finished_jobs(store_, layout_, {.keep_days = 30, .keep_jobs = 0}, now_ms());
  EXPECT_TRUE(report.jobs.empty());
  EXPECT_EQ(report.folders_removed, 1);
  EXPECT_FALSE(fs::exists(layout_.done(id)));
  EXPECT_TRUE(store_.purged_folders().empty());
}

// Makes `dir` unremovable for this process and undoes it: without write permission for a
// normal user; root ignores permissions, so for root a file inside is made immutable
// (FS_IMMUTABLE_FL, as chattr +i). False if neither can be done here.
class Unremovable {
 public:
  explicit Unremovable(const fs::path& dir) : dir_(dir) {
    if (::geteuid() != 0) {
      fs::permissions(dir_, fs::perms::owner_read | fs::perms::owner_exec);
      ok_ = true;
      return;
    }
    write_file(dir_ / "pinned", "x");
    fd_ = ::open((dir_ / "pinned").c_str(), O_RDONLY | O_CLOEXEC);
    ok_ = fd_ >= 0 && set_flag(true);
  }
  ~Unremovable() { release(); }
  void release() {
    if (fd_ >= 0) {
      set_flag(false);
      ::close(fd_);
      fd_ = -1;
    } else if (ok_) {
      fs::permissions(dir_, fs::perms::owner_all);
    }
    ok_ = false;
  }
  bool ok() const { return ok_; }

 private:
  bool set_flag(bool on) {
    int flags = 0;
    if (::ioctl(fd_, FS_IOC_GETFLAGS, &flags) != 0) return false;
    flags = on ? (flags | FS_IMMUTABLE_FL) : (flags & ~FS_IMMUTABLE_FL);
    return ::ioctl(fd_, FS_IOC_SETFLAGS, &flags) == 0;
  }
  fs::path dir_;
  int fd_ = -1;
  bool ok_ = false;
};

TEST_F(Purge, AFolderThatCannotBeRemovedIsTriedAgainAtTheNextPass) {
  const int64_t id = job(JobState::completed, 40 * kDay);
  Unremovable pin(layout_.done(id));
  if (!pin.ok()) GTEST_SKIP() << "this file system cannot make " << layout_.done(id) << " unremovable for root";
  PurgeReport report = purge_finished_jobs(store_, layout_, {.keep_days = 30, .keep_jobs = 0}, now_ms());
  EXPECT_EQ(report.jobs, std::vector<int64_t>{id});
  ASSERT_EQ(report.problems.size(), 1u);
  EXPECT_NE(report.problems[0].find(layout_.done(id).string()), std::string::npos) << report.problems[0];
  EXPECT_EQ(store_.purged_folders().size(), 1u);
  pin.release();
  report = purge_finished_jobs(store_, layout_, {.keep_days = 30, .keep_jobs = 0}, now_ms());
  EXPECT_EQ(report.folders_removed, 1);
  EXPECT_FALSE(fs::exists(layout_.done(id)));
}

// The worker's passes, counted from its on_pass hook.
class Passes {
 public:
  void add(const PurgeReport& r) {
    std::lock_guard lock(mu_);
    reports_.push_back(r);
    cv_.notify_all();
  }
  // The pass number `n` (1-based), once it has happened.
  PurgeReport await(size_t n) {
    std::unique_lock lock(mu_);
    EXPECT_TRUE(cv_.wait_for(lock, std::chrono::seconds(60), [&] { return reports_.size() >= n; }))
        << "pass " << n << " never ran";
    return reports_.size() >= n ? reports_[n - 1] : PurgeReport{};
  }
  size_t count() {
    std::lock_guard lock(mu_);
    return reports_.size();
  }

 private:
  std::mutex mu_;
  std::condition_variable cv_;
  std::vector<PurgeReport> reports_;
};

TEST_F(Purge, TheWorkerPurgesAtStartAndThenEveryPeriodWithThePolicyOfTheMoment) {
  FakeClock clock;
  Passes passes;
  std::atomic<int> keep_days{30};
  const int64_t old_job = job(JobState::completed, 40 * kDay);
  const int64_t ten_days = job(JobState::completed, 10 * kDay);
  PurgeWorker worker(store_, layout_, [&] { return RetentionPolicy{keep_days.load(), 0}; }, clock,
                     std::chrono::hours(1), [&](const PurgeReport& r) { passes.add(r); });
  worker.start();
  EXPECT_EQ(passes.await(1).jobs, std::vector<int64_t>{old_job}) << "the pass at start-up";
  EXPECT_FALSE(store_.get(old_job));
  keep_days = 7;  // a reloaded config
  clock.await_waiters(1);  // the worker waits for the next hour
  clock.advance(std::chrono::minutes(59));
  clock.await_waiters(1);
  EXPECT_EQ(passes.count(), 1u) << "no pass before the hour is up";
  EXPECT_TRUE(store_.get(ten_days));
  clock.advance(std::chrono::minutes(1));
  EXPECT_EQ(passes.await(2).jobs, std::vector<int64_t>{ten_days});
  EXPECT_FALSE(fs::exists(layout_.done(ten_days)));
  worker.stop();
}

TEST_F(Purge, AWakeRunsAPassAtOnceAsAfterAReload) {
  FakeClock clock;
  Passes passes;
  std::atomic<int> keep_jobs{0};
  const int64_t a = job(JobState::completed, 3000);
  const int64_t b = job(JobState::completed, 2000);
  PurgeWorker worker(store_, layout_, [&] { return RetentionPolicy{0, keep_jobs.load()}; }, clock,
                     std::chrono::hours(1), [&](const PurgeReport& r) { passes.add(r); });
  worker.start();
  EXPECT_TRUE(passes.await(1).jobs.empty()) << "no limit: nothing to purge";
  keep_jobs = 1;  // the config reloaded with [store] keep_jobs = 1
  worker.wake();
  EXPECT_EQ(passes.await(2).jobs, std::vector<int64_t>{a}) << "without waiting for the hour";
  EXPECT_TRUE(store_.get(b));
  worker.stop();
}

}  // namespace
}  // namespace atelier
