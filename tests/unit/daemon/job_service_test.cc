// The job life cycle on disk: claiming (rename first, then examine what was claimed, so
// nothing can be swapped in between) and crash safety: whatever step a kill -9 interrupts,
// recover() ends each job in the state it was going to, and nothing is lost or converted twice.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <fstream>
#include <system_error>

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

// Claiming: the entry is renamed into work/<id>/ first and examined there (opened with
// O_NOFOLLOW, fstat of the descriptor), so nothing can be swapped in between check and use.
namespace {

std::string failed_reason(Spool& s, int64_t id) { return s.store.get(id)->reason; }

}  // namespace

TEST(JobServiceClaim, AnImageSwappedForASymlinkJustBeforeTheRenameFailsAndIsNeverFollowed) {
  Spool s;
  const fs::path secret = s.tmp.path() / "secret.png";
  atelier::test::write_file(secret, "somebody else's picture");
  const fs::path entry = s.layout.incoming("knit") / "cat.png";
  atelier::test::write_file(entry, "a real picture");
  // The attacker's move, at the worst moment: after claim.json is written and fsynced (where
  // the old order had already checked the entry), before the rename.
  s.jobs.set_claim_hook([&](const std::string& step) {
    if (step != "intent") return;
    fs::remove(entry);
    fs::create_symlink(secret, entry);
  });
  const int64_t id = *s.jobs.claim(entry);
  auto job = s.store.get(id);
  EXPECT_EQ(job->state, JobState::failed) << "a swapped-in symlink must never be queued for the converter";
  EXPECT_NE(job->reason.find("symbolic links are not accepted"), std::string::npos) << job->reason;
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(s.layout.failed(id) / "cat.png"))) << "kept, not followed";
  EXPECT_EQ(atelier::test::read_file(secret), "somebody else's picture");
}

TEST(JobServiceClaim, FoldersFifosAndSymlinksFailWithTheirReasonWithoutBlocking) {
  Spool s;
  fs::create_symlink("/etc/passwd", s.layout.incoming("knit") / "link.png");
  fs::create_directory(s.layout.incoming("knit") / "album.png");
  ASSERT_EQ(mkfifo((s.layout.incoming("knit") / "pipe.png").c_str(), 0644), 0);
  const std::pair<const char*, const char*> cases[] = {
      {"link.png", "symbolic links are not accepted"},
      {"album.png", "folders are not accepted in incoming/knit/"},
      {"pipe.png", "FIFO"}};
  for (const auto& [name, why] : cases) {
    const int64_t id = *s.jobs.claim(s.layout.incoming("knit") / name);  // a FIFO must not block
    EXPECT_EQ(s.store.get(id)->state, JobState::failed) << name;
    EXPECT_NE(failed_reason(s, id).find(name), std::string::npos) << failed_reason(s, id);
    EXPECT_NE(failed_reason(s, id).find(why), std::string::npos) << failed_reason(s, id);
    EXPECT_TRUE(fs::exists(fs::symlink_status(s.layout.failed(id) / name))) << name << " kept in failed/";
  }
}

TEST(JobServiceClaim, ACompanionThatIsASymlinkOrNotARegularFileFailsTheJobNamingIt) {
  Spool s;
  const fs::path secret = s.tmp.path() / "private.toml";
  atelier::test::write_file(secret, "width = 12\n");
  atelier::test::write_file(s.layout.incoming("knit") / "cat.png", "picture");
  fs::create_symlink(secret, s.layout.incoming("knit") / "cat.png.toml");
  const int64_t cat = *s.jobs.claim(s.layout.incoming("knit") / "cat.png");
  EXPECT_EQ(s.store.get(cat)->state, JobState::failed);
  EXPECT_NE(failed_reason(s, cat).find("cat.png.toml"), std::string::npos) << failed_reason(s, cat);
  EXPECT_NE(failed_reason(s, cat).find("symbolic links"), std::string::npos) << failed_reason(s, cat);
  // Both kept, nothing lost; the symlink still a symlink and its target untouched.
  EXPECT_EQ(atelier::test::read_file(s.layout.failed(cat) / "cat.png"), "picture");
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(s.layout.failed(cat) / "cat.png.toml")));
  EXPECT_EQ(atelier::test::read_file(secret), "width = 12\n");

  atelier::test::write_file(s.layout.incoming("knit") / "dog.png", "picture");
  fs::create_directory(s.layout.incoming("knit") / "dog.png.relax.png");
  const int64_t dog = *s.jobs.claim(s.layout.incoming("knit") / "dog.png");
  EXPECT_EQ(s.store.get(dog)->state, JobState::failed);
  EXPECT_NE(failed_reason(s, dog).find("dog.png.relax.png"), std::string::npos) << failed_reason(s, dog);
  EXPECT_TRUE(fs::is_directory(s.layout.failed(dog) / "dog.png.relax.png"));

  // A regular sidecar still travels with its image into a queued job.
  atelier::test::write_file(s.layout.incoming("knit") / "owl.png", "picture");
  atelier::test::write_file(s.layout.incoming("knit") / "owl.png.toml", "width = 30\n");
  const int64_t owl = *s.jobs.claim(s.layout.incoming("knit") / "owl.png");
  EXPECT_EQ(s.store.get(owl)->state, JobState::queued);
  EXPECT_TRUE(fs::is_regular_file(s.layout.work(owl) / "owl.png.toml"));
}

TEST(JobServiceClaim, ATransientFailureLeavesTheFileInIncomingAndATryLaterClaimsIt) {
  for (const char* step : {"intent", "claimed", "examined"}) {
    Spool s;
    const fs::path entry = s.layout.incoming("knit") / "cat.png";
    atelier::test::write_file(entry, "picture");
    atelier::test::write_file(s.layout.incoming("knit") / "cat.png.toml", "width = 30\n");
    s.jobs.set_claim_hook([&](const std::string& at) {
      if (at == step) throw std::system_error(EMFILE, std::generic_category(), "open");
    });
    try {
      s.jobs.claim(entry);
      ADD_FAILURE() << step << ": the claim should have failed";
    } catch (const atelier::PickupError& e) {
      EXPECT_TRUE(e.transient()) << e.what();
      EXPECT_NE(std::string(e.what()).find("cat.png"), std::string::npos) << e.what();
    }
    EXPECT_EQ(atelier::test::read_file(entry), "picture") << step << ": back in incoming/";
    EXPECT_TRUE(fs::exists(s.layout.incoming("knit") / "cat.png.toml")) << step;
    EXPECT_TRUE(fs::is_empty(s.layout.work())) << step;
    EXPECT_TRUE(s.store.list({}).empty()) << step;

    s.jobs.set_claim_hook(nullptr);
    const int64_t id = *s.jobs.claim(entry);
    EXPECT_EQ(s.store.get(id)->state, JobState::queued) << step;
    EXPECT_TRUE(fs::exists(s.layout.work(id) / "cat.png.toml")) << step;
  }
}

TEST(JobServiceClaim, ALastingFailureIsNotTransient) {
  Spool s;
  atelier::test::write_file(s.layout.incoming("knit") / "cat.png", "picture");
  s.jobs.set_claim_hook([&](const std::string& at) {
    if (at == "claimed") throw std::system_error(EACCES, std::generic_category(), "open");
  });
  try {
    s.jobs.claim(s.layout.incoming("knit") / "cat.png");
    ADD_FAILURE() << "the claim should have failed";
  } catch (const atelier::PickupError& e) {
    EXPECT_FALSE(e.transient()) << e.what();
  }
  EXPECT_TRUE(fs::exists(s.layout.incoming("knit") / "cat.png"));
}

TEST(JobServiceRecovery, AClaimCutOffBeforeItsExaminationIsExaminedWhenAdopted) {
  Spool s;
  // Crash after the rename, before the examination: a symlink sits in work/3 unexamined.
  for (int i = 0; i < 3; ++i) s.store.reserve_id();
  fs::create_directories(s.layout.work(3));
  fs::create_symlink("/etc/passwd", s.layout.work(3) / "link.png");
  atelier::test::write_file(s.layout.work(3) / "claim.json",
                            R"({"kind": "knit", "name": "link.png", "folder": "knit", "examined": false})");
  // Crash before the rename: claim.json only; the file is still in incoming/.
  const int64_t early = s.store.reserve_id();
  fs::create_directories(s.layout.work(early));
  atelier::test::write_file(s.layout.work(early) / "claim.json",
                            R"({"kind": "knit", "name": "dog.png", "folder": "knit", "examined": false})");

  EXPECT_TRUE(s.jobs.recover().empty()) << "an unexamined symlink must never be queued";
  EXPECT_EQ(s.store.get(3)->state, JobState::failed);
  EXPECT_NE(s.store.get(3)->reason.find("symbolic links"), std::string::npos);
  EXPECT_FALSE(s.store.has_job(early));
  EXPECT_FALSE(fs::exists(s.layout.work(early)));
}

TEST(JobServiceClaim, AJobFileIsClaimedBeforeItsKindIsReadAndTheDaemonNeverParsesIt) {
  atelier::test::TempDir tmp;
  const SpoolLayout layout{tmp.path() / "spool"};
  Store store{tmp.path() / "jobs.sqlite"};
  std::vector<fs::path> asked;
  JobService jobs{store, layout, nullptr, [&](const fs::path& file, const std::string& shown) {
                    asked.push_back(file);
                    if (shown == "bad.toml") return atelier::JobFileKind{"", "bad.toml:1:1: not a TOML job file"};
                    return atelier::JobFileKind{"lace", ""};
                  }};
  jobs.ensure_layout();
  atelier::test::write_file(layout.incoming() / "eyelets.toml", "kind = \"lace\"\n");
  atelier::test::write_file(layout.incoming() / "bad.toml", "\x01\x02");
  const int64_t good = *jobs.claim(layout.incoming() / "eyelets.toml");
  const int64_t bad = *jobs.claim(layout.incoming() / "bad.toml");
  ASSERT_EQ(asked.size(), 2u);
  EXPECT_EQ(asked[0], layout.work(good) / "eyelets.toml") << "the probe reads the claimed file";
  EXPECT_EQ(store.get(good)->kind, "lace");
  EXPECT_EQ(store.get(good)->state, JobState::queued);
  EXPECT_EQ(store.get(bad)->state, JobState::failed);
  EXPECT_EQ(store.get(bad)->reason, "bad.toml:1:1: not a TOML job file");
}
