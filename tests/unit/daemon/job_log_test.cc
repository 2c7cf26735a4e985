// The job's story in the log (daemon/job_log.h), read from a capturing sink as the journal
// would hold it: one record per state change with JOB_ID, KIND, DEVICE (once a machine has the
// job) and STATE; progress at most once per tenth; notes without STATE; failures as warnings
// with their reason.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <string>
#include <vector>

#include "base/fake_clock.h"
#include "daemon/job_log.h"
#include "daemon/job_service.h"
#include "daemon/knit_device.h"
#include "tests/e2e/daemon_harness.h"
#include "tests/support/job_watch.h"
#include "tests/support/log_capture.h"
#include "tests/support/simulated_knitter.h"

namespace atelier {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::StartsWith;

// A spool whose JobService tells a JobLog (as the daemon's does) and a JobWatch.
struct LoggedSpool {
  test::TempDir tmp;
  SpoolLayout layout{tmp.path() / "spool"};
  Store store{tmp.path() / "jobs.sqlite"};
  FakeClock clock;
  test::JobWatch watch{clock};
  JobLog job_log;
  test::LogCapture log;
  JobService jobs{store, layout, [this, told = watch.listener()](const JobChange& change) {
                    job_log.on_change(change);
                    told(change);
                  }};
  LoggedSpool() { jobs.ensure_layout(); }

  int64_t drop(const std::string& kind, const std::string& name) {
    test::write_file(layout.incoming(kind) / name, "bytes of " + name);
    return *jobs.claim(layout.incoming(kind) / name);
  }
};

bool is_progress(const log::Record& r) { return std::regex_search(r.message, std::regex("^[1-9]0 %")); }

TEST(JobLogStory, AKnitJobTellsEachStateOnceWithItsFieldsAndAFewProgressLines) {
  LoggedSpool s;
  const int64_t id = s.drop("knit", "cat.png");
  s.jobs.transition(id, JobState::converting, "converting");
  // What the converter writes: a 40-row pattern of 20 stitches.
  cv::Mat pattern(40, 20, CV_8UC1, cv::Scalar(255));
  for (int r = 0; r < 40; ++r) pattern.at<uint8_t>(r, r % 20) = 0;
  cv::imwrite(s.store.get(id)->work_dir + "/pattern.png", pattern);
  s.jobs.finish_converted(id, JobState::ready, "converted; waiting for knitter");

  DeviceConfig d;
  d.name = "knitter";
  d.driver = "ayab";
  d.port = "/dev/ttyKNIT";
  d.machine = "kh930";
  d.kinds = {"knit"};
  d.autostart = true;
  test::SimulatedKnitter machine(s.clock, 2);
  KnitDevice device(
      d, s.jobs, [&machine](const std::string&) { return machine.open(); },
      [port = d.port]() -> std::optional<std::string> { return port; }, {}, s.clock);
  device.start_worker();
  device.wake();
  ASSERT_TRUE(s.watch.wait_left(id, JobState::running));
  device.stop();
  ASSERT_EQ(s.store.get(id)->state, JobState::completed);

  EXPECT_THAT(s.log.states_of(id), ElementsAre("queued", "converting", "ready", "running", "completed"));
  std::vector<std::string> lines;
  int progress = 0;
  for (const log::Record& r : s.log.for_job(id)) {
    EXPECT_EQ(r.fields.kind, "knit") << r.message;
    lines.push_back(log::text(r));
    if (is_progress(r)) {
      ++progress;
      EXPECT_EQ(r.fields.state, "") << "progress is no state change: " << r.message;
      EXPECT_EQ(r.fields.device, "knitter") << r.message;
    }
  }
  EXPECT_EQ(progress, 9) << "10 % ... 90 % of 40 rows, not one line per row";
  EXPECT_THAT(lines, ::testing::Contains("job " + std::to_string(id) +
                                         " (knit): queued: cat.png, dropped into the hot folder"));
  EXPECT_THAT(lines, ::testing::Contains("job " + std::to_string(id) + " (knit): ready: converted; waiting for knitter"));
  EXPECT_THAT(lines, ::testing::Contains("job " + std::to_string(id) + " (knit, knitter): running: knitting on knitter"));
  EXPECT_THAT(lines, ::testing::Contains(StartsWith("job " + std::to_string(id) +
                                                    " (knit, knitter): 50 %: knitting row 21 of 40")));
  EXPECT_EQ(lines.back(), "job " + std::to_string(id) + " (knit, knitter): completed: knitted 40 rows on knitter");
  EXPECT_EQ(lines.size(), 5u + 9u) << ::testing::PrintToString(lines);
}

TEST(JobLogStory, AFailureIsAWarningWithItsReason) {
  LoggedSpool s;
  const int64_t id = s.drop("knit", "notes.png");
  s.jobs.transition(id, JobState::converting, "converting");
  s.jobs.fail(id, "notes.png: not an image (no decoder recognises it)");
  const std::vector<log::Record> records = s.log.for_job(id);
  ASSERT_FALSE(records.empty());
  const log::Record& last = records.back();
  EXPECT_EQ(last.priority, log::Priority::warning);
  EXPECT_EQ(last.fields.state, "failed");
  EXPECT_EQ(log::text(last), "job " + std::to_string(id) + " (knit): failed: notes.png: not an image (no decoder recognises it)");
}

TEST(JobLogStory, AnEntryRejectedAtPickUpIsQueuedThenFailedWithTheProblem) {
  LoggedSpool s;
  std::filesystem::create_directories(s.layout.incoming("knit") / "photos");
  const int64_t id = *s.jobs.claim(s.layout.incoming("knit") / "photos");
  EXPECT_THAT(s.log.states_of(id), ElementsAre("queued", "failed"));
  EXPECT_THAT(log::text(s.log.for_job(id).back()), HasSubstr("failed: photos: folders are not accepted"));
}

TEST(JobLogStory, ACancelAndARetryAreStateChangesToo) {
  LoggedSpool s;
  const int64_t id = s.drop("knit", "cat.png");
  s.jobs.fail(id, "canceled by user before conversion", JobState::canceled);
  s.jobs.retry(id);
  EXPECT_THAT(s.log.states_of(id), ElementsAre("queued", "canceled", "queued"));
  const std::vector<log::Record> records = s.log.for_job(id);
  EXPECT_EQ(records[1].message, "canceled by user before conversion");
  EXPECT_EQ(records[1].priority, log::Priority::info);
  EXPECT_EQ(records[2].message, "queued: retry requested");
}

TEST(JobLogStory, ANoteIsLoggedWithoutAState) {
  LoggedSpool s;
  const int64_t id = s.drop("cut", "box.svg");
  s.jobs.note(id, "paused by the program (M0): swap the veneer sheet");
  const std::vector<log::Record> records = s.log.for_job(id);
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[1].message, "queued: paused by the program (M0): swap the veneer sheet");
  EXPECT_EQ(records[1].fields.state, "");
  EXPECT_EQ(records[1].fields.kind, "cut");
}

TEST(JobLogStory, AMoveToDoneCutOffByACrashIsLoggedWhenRecoveryFinishesIt) {
  LoggedSpool s;
  const int64_t id = s.drop("knit", "cat.png");
  s.jobs.transition(id, JobState::converting, "converting");
  // What finish_converted(id, ready) does before its store transaction: the crash hits there.
  test::write_file(s.layout.work(id) / "finish.json", R"({"to": "ready", "reason": "converted; waiting for knitter"})");
  std::filesystem::rename(s.layout.work(id), s.layout.done(id));
  s.jobs.recover();
  EXPECT_THAT(s.log.states_of(id), ElementsAre("queued", "converting", "ready"));
  EXPECT_EQ(s.log.for_job(id).back().message, "ready: converted; waiting for knitter");
}

TEST(JobLogProgress, OneRecordPerTenthPassedHoweverOftenProgressIsReported) {
  LoggedSpool s;
  const int64_t id = s.drop("cut", "box.svg");
  for (int acked = 0; acked <= 1000; ++acked)
    s.jobs.progress(id, acked, 1000, std::to_string(acked) + " of 1000 lines");
  std::vector<std::string> messages;
  for (const log::Record& r : s.log.for_job(id))
    if (is_progress(r)) messages.push_back(r.message);
  EXPECT_THAT(messages, ElementsAre("10 %: 100 of 1000 lines", "20 %: 200 of 1000 lines", "30 %: 300 of 1000 lines",
                                    "40 %: 400 of 1000 lines", "50 %: 500 of 1000 lines", "60 %: 600 of 1000 lines",
                                    "70 %: 700 of 1000 lines", "80 %: 800 of 1000 lines", "90 %: 900 of 1000 lines"));
}

TEST(JobLogProgress, AJumpPastSeveralTenthsIsOneRecordAndNoTotalSaysNothing) {
  LoggedSpool s;
  const int64_t id = s.drop("knit", "cat.png");
  const size_t before = s.log.for_job(id).size();
  s.jobs.progress(id, 0, 0, "starting");
  s.jobs.progress(id, 2, 3, "knitted row 2 of 3");
  s.jobs.progress(id, 3, 3, "knitted row 3 of 3");  // the end is the completion's to say
  const std::vector<log::Record> records = s.log.for_job(id);
  ASSERT_EQ(records.size(), before + 1);
  EXPECT_EQ(records.back().message, "60 %: knitted row 2 of 3");
}

TEST(JobLogFields, AJobKnownByIdOnlyGetsItsKindAndDeviceFromTheStore) {
  LoggedSpool s;
  const int64_t id = s.drop("knit", "cat.png");
  const log::Fields f = job_fields(s.store, id, "knitter");
  EXPECT_EQ(f.job_id, id);
  EXPECT_EQ(f.kind, "knit");
  EXPECT_EQ(f.device, "knitter");
  const log::Fields unknown = job_fields(s.store, 999);
  EXPECT_EQ(unknown.job_id, 999);
  EXPECT_EQ(unknown.kind, "");
}

}  // namespace
}  // namespace atelier
