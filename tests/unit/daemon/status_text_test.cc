// systemd's one-line status of the daemon (sd_notify STATUS=, `systemctl status atelierd`)
// counts every job a user would look for: waiting, converting, ready for a machine, on a
// machine, done and failed.
#include <gtest/gtest.h>

#include "daemon/status_text.h"

namespace atelier {
namespace {

TEST(StatusText, CountsReadyAndRunningJobsBesideQueuedConvertingCompletedAndFailed) {
  std::map<JobState, int64_t> counts = {{JobState::queued, 3},    {JobState::converting, 1}, {JobState::ready, 2},
                                        {JobState::running, 1},   {JobState::completed, 40}, {JobState::failed, 2},
                                        {JobState::canceled, 0},  {JobState::interrupted, 0}};
  EXPECT_EQ(status_text(counts), "3 queued, 1 converting, 2 ready, 1 running, 40 completed, 2 failed");
}

TEST(StatusText, InterruptedAndCanceledJobsShowOnlyWhenThereAreSome) {
  std::map<JobState, int64_t> counts = {{JobState::running, 0}, {JobState::interrupted, 1}, {JobState::canceled, 4}};
  EXPECT_EQ(status_text(counts), "0 queued, 0 converting, 0 ready, 0 running, 0 completed, 0 failed, 4 canceled, 1 interrupted");
}

TEST(StatusText, AnEmptyStoreSaysZeroForEachState) {
  EXPECT_EQ(status_text({}), "0 queued, 0 converting, 0 ready, 0 running, 0 completed, 0 failed");
}

}  // namespace
}  // namespace atelier
