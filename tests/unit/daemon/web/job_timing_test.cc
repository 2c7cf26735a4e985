// Elapsed time and time left on the web page's job list.
#include "daemon/web/job_timing.h"

#include <gtest/gtest.h>

namespace atelier::web {
namespace {

Job job(JobState state, int64_t created_ms, int64_t updated_ms, int64_t done = 0, int64_t total = 0) {
  Job j;
  j.state = state;
  j.created_ms = created_ms;
  j.updated_ms = updated_ms;
  j.progress_done = done;
  j.progress_total = total;
  return j;
}

TEST(JobTiming, AFinishedJobTookFromCreationToItsLastChange) {
  const JobTiming t = job_timing(job(JobState::completed, 1000, 61000), std::nullopt, 999999, std::nullopt);
  EXPECT_DOUBLE_EQ(t.elapsed_s, 60.0);
  EXPECT_FALSE(t.state_s);
  EXPECT_FALSE(t.time_left_s);
}

TEST(JobTiming, ARunningJobExtrapolatesItsOwnPace) {
  // 30 of 120 rows in the 60 s since it started running: 90 rows more take 180 s.
  const JobTiming t = job_timing(job(JobState::running, 0, 10000, 30, 120), 40000, 100000, std::nullopt);
  EXPECT_DOUBLE_EQ(t.elapsed_s, 100.0);
  ASSERT_TRUE(t.state_s);
  EXPECT_DOUBLE_EQ(*t.state_s, 60.0);
  ASSERT_TRUE(t.time_left_s);
  EXPECT_DOUBLE_EQ(*t.time_left_s, 180.0);
}

TEST(JobTiming, TheDevicesOwnEstimateWins) {
  const JobTiming t = job_timing(job(JobState::running, 0, 0, 30, 120), 0, 60000, 12.5);
  ASSERT_TRUE(t.time_left_s);
  EXPECT_DOUBLE_EQ(*t.time_left_s, 12.5);
}

TEST(JobTiming, NoEstimateBeforeProgressOrWhileWaiting) {
  EXPECT_FALSE(job_timing(job(JobState::converting, 0, 0, 0, 100), 0, 5000, std::nullopt).time_left_s);
  EXPECT_FALSE(job_timing(job(JobState::ready, 0, 0, 100, 100), 0, 5000, std::nullopt).time_left_s);
  EXPECT_FALSE(job_timing(job(JobState::running, 0, 0, 10, 100), std::nullopt, 5000, std::nullopt).time_left_s);
  const JobTiming converting = job_timing(job(JobState::converting, 0, 0, 50, 100), 1000, 5000, std::nullopt);
  ASSERT_TRUE(converting.time_left_s);
  EXPECT_DOUBLE_EQ(*converting.time_left_s, 4.0);
}

}  // namespace
}  // namespace atelier::web
