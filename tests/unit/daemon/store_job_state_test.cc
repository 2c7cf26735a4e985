// Job state names and the allowed edges of the job state machine (daemon/store_job_state.cc,
// declared in daemon/store.h).
#include <gtest/gtest.h>

#include "daemon/store.h"
#include "tests/unit/daemon/store_fixture.h"

namespace atelier {
namespace {

using test::kAllowed;
using test::kAllStates;
using test::S;

TEST(StoreStates, NamesRoundTripAndUnknownNamesAreRejected) {
  for (JobState s : kAllStates) EXPECT_EQ(state_from_name(state_name(s)), s);
  EXPECT_EQ(state_name(S::interrupted), "interrupted");
  EXPECT_FALSE(state_from_name("Queued").has_value());
  EXPECT_FALSE(state_from_name("").has_value());
}

TEST(StoreStates, AllowedEdgesMatchTheDesign) {
  for (JobState from : kAllStates) {
    for (JobState to : kAllStates) {
      EXPECT_EQ(transition_allowed(from, to), kAllowed.count({from, to}) == 1)
          << state_name(from) << " -> " << state_name(to);
    }
  }
}

}  // namespace
}  // namespace atelier
