// Retention's choice of finished jobs to purge (daemon/retention.h): by age, by count, both,
// and neither when a limit is 0.
#include "daemon/retention.h"

#include <gtest/gtest.h>

namespace atelier {
namespace {

constexpr int64_t kDay = int64_t{24} * 60 * 60 * 1000;
constexpr int64_t kNow = int64_t{1800000000} * 1000;  // 2027-01-15

TEST(Retention, JobsFinishedMoreThanKeepDaysAgoArePurged) {
  const std::vector<FinishedJob> jobs = {
      {1, kNow - 40 * kDay}, {2, kNow - 30 * kDay - 1}, {3, kNow - 30 * kDay}, {4, kNow - kDay}, {5, kNow}};
  EXPECT_EQ(jobs_to_purge(jobs, {.keep_days = 30, .keep_jobs = 0}, kNow), (std::vector<int64_t>{1, 2}));
  EXPECT_EQ(jobs_to_purge(jobs, {.keep_days = 1, .keep_jobs = 0}, kNow), (std::vector<int64_t>{1, 2, 3}));
  EXPECT_TRUE(jobs_to_purge(jobs, {.keep_days = 0, .keep_jobs = 0}, kNow).empty()) << "0 = keep forever";
}

TEST(Retention, OnlyTheKeepJobsMostRecentlyFinishedAreKept) {
  // Job 1 was retried and finished last: it is the newest, although its id is the oldest.
  const std::vector<FinishedJob> jobs = {{1, kNow - 1}, {2, kNow - 5}, {3, kNow - 4}, {4, kNow - 3}};
  EXPECT_EQ(jobs_to_purge(jobs, {.keep_days = 0, .keep_jobs = 2}, kNow), (std::vector<int64_t>{2, 3}));
  EXPECT_EQ(jobs_to_purge(jobs, {.keep_days = 0, .keep_jobs = 4}, kNow), std::vector<int64_t>{});
  EXPECT_TRUE(jobs_to_purge(jobs, {.keep_days = 0, .keep_jobs = 0}, kNow).empty()) << "0 = no limit";
  // Equal times: the higher id is the newer.
  EXPECT_EQ(jobs_to_purge({{7, kNow}, {8, kNow}, {9, kNow}}, {.keep_days = 0, .keep_jobs = 1}, kNow),
            (std::vector<int64_t>{7, 8}));
}

TEST(Retention, BothLimitsApply) {
  const std::vector<FinishedJob> jobs = {{1, kNow - 100 * kDay}, {2, kNow - 3}, {3, kNow - 2}, {4, kNow - 1}};
  EXPECT_EQ(jobs_to_purge(jobs, {.keep_days = 30, .keep_jobs = 2}, kNow), (std::vector<int64_t>{1, 2}));
  EXPECT_TRUE(jobs_to_purge({}, {}, kNow).empty());
}

TEST(Retention, TheDefaultsKeepThirtyDaysAndFiveHundredJobs) {
  const RetentionPolicy policy;
  EXPECT_EQ(policy.keep_days, 30);
  EXPECT_EQ(policy.keep_jobs, 500);
}

}  // namespace
}  // namespace atelier
