// Crash safety of the job life cycle: whatever step a kill -9 interrupts, recover() ends
// each job in the state it was going to, and nothing is lost or converted twice.
#include <gtest/gtest.h>

#include <fstream>

#include "daemon/job_service.h"
#include "tests/e2e/daemon_harness.h"

namespace fs = std::filesystem;
using atelier::Job;
using atelier::JobService;
using atelier::JobState;
using atelier::SpoolLayout;
using atelier::Store;

namespace {

struct Spool {
  atelier::test::TempDir tmp;
  SpoolLayout layout{tmp.path() / "spool"};
  Store store{tmp.path() / "jobs.sqlite"};
  JobService jobs{store, layout, nullptr};
  Spool() { jobs.ensure_layout(); }

  int64_t drop_and_claim(const std::string& name) {
    atelier::test::write_file(layout.incoming("knit") / name, "bytes of " + name);
    return *jobs.claim(layout.incoming("knit") / name);
  }
};

}  // namespace

TEST(JobServiceRecovery, AMoveToDoneCutOffByACrashEndsInTheStateItWasGoingTo) {
  Spool s;
  const int64_t id = s.drop_and_claim("cat.png");
  s.jobs.transition(id, JobState::converting, "converting");
  // What finish_converted(id, ready) does before its store transaction: the crash hits there.
  atelier::test::write_file(s.layout.work(id) / "finish.json", R"({"to": "ready", "reason": "converted; waiting for knitter"})");
  fs::rename(s.layout.work(id), s.layout.done(id));

  EXPECT_TRUE(s.jobs.recover().empty());
  auto job = s.store.get(id);
  EXPECT_EQ(job->state, JobState::ready);
  EXPECT_EQ(job->output_dir, s.layout.done(id).string());
  EXPECT_FALSE(fs::exists(s.layout.done(id) / "finish.json"));
}

TEST(JobServiceRecovery, ARejectedEntryWhoseFailureWasCutOffIsFailedNotConverted) {
  Spool s;
  fs::create_symlink("/etc/passwd", s.layout.incoming("knit") / "link.png");
  const int64_t id = *s.jobs.claim(s.layout.incoming("knit") / "link.png");
  ASSERT_EQ(s.store.get(id)->state, JobState::failed);
  // The same claim as the crash would have left it: row queued, entry still in work/<id>.
  Spool t;
  fs::create_directories(t.layout.work(1));
  fs::create_symlink("/etc/passwd", t.layout.work(1) / "link.png");
  atelier::test::write_file(t.layout.work(1) / "claim.json",
                            R"({"kind": "knit", "name": "link.png", "problem": "link.png: symbolic links are not accepted"})");
  ASSERT_EQ(t.store.reserve_id(), 1);
  Job job;
  job.id = 1;
  job.kind = "knit";
  job.name = "link.png";
  job.work_dir = t.layout.work(1).string();
  t.store.insert_job(job);

  EXPECT_TRUE(t.jobs.recover().empty()) << "a rejected entry must never be queued for conversion";
  EXPECT_EQ(t.store.get(1)->state, JobState::failed);
  EXPECT_NE(t.store.get(1)->reason.find("symbolic links"), std::string::npos);
}

TEST(JobServiceRecovery, AClaimedFileWithoutARowIsAdoptedOnceAndAHalfCopiedSubmitIsDropped) {
  Spool s;
  // Crash between the claim's rename and its row: the file sits in work/7 with claim.json.
  for (int i = 0; i < 7; ++i) s.store.reserve_id();
  fs::create_directories(s.layout.work(7));
  atelier::test::write_file(s.layout.work(7) / "dog.png", "bytes");
  atelier::test::write_file(s.layout.work(7) / "claim.json", R"({"kind": "knit", "name": "dog.png", "problem": ""})");
  // Crash in the middle of a submit's copy: no claim.json yet.
  const int64_t half = s.store.reserve_id();
  fs::create_directories(s.layout.work(half));
  atelier::test::write_file(s.layout.work(half) / ".copy-big.png", "half of it");

  EXPECT_EQ(s.jobs.recover(), std::vector<int64_t>{7});
  EXPECT_EQ(s.store.get(7)->name, "dog.png");
  EXPECT_FALSE(s.store.has_job(half));
  EXPECT_FALSE(fs::exists(s.layout.work(half)));
  EXPECT_EQ(s.jobs.recover(), std::vector<int64_t>{7}) << "adopted once, not twice";
}

TEST(JobServiceRecovery, EveryPendingJobIsRequeuedHoweverManyThereAre) {
  Spool s;
  for (int i = 0; i < 1200; ++i) {
    Job job;
    job.id = s.store.reserve_id();
    job.kind = "knit";
    job.name = "f" + std::to_string(i) + ".png";
    job.work_dir = s.layout.work(job.id).string();
    fs::create_directories(job.work_dir);
    s.store.insert_job(job);
  }
  EXPECT_EQ(s.jobs.recover().size(), 1200u);
}
