// tools/torture-kill9 for three rounds of up to three files (about 10 s): real images, SVGs
// and lace job files dropped, the daemon (and sometimes a converter) kill -9'd at random
// moments, and at the end every dropped file is in exactly one job, none stuck, the store
// intact. The long run (100 rounds)
// is done by hand: `nice tools/torture-kill9 --rounds 100`.
#include <gtest/gtest.h>

#include "tests/e2e/daemon_harness.h"

namespace atelier {
namespace {

TEST(E2ETortureKill9, ThreeRoundsLoseDoubleAndStickNothing) {
  const auto result = test::run_command({std::string(ATELIER_SOURCE_DIR) + "/tools/torture-kill9", "--rounds",
                                         "3", "--burst", "3", "--seed", "17", "--build", ATELIER_BINARY_DIR});
  EXPECT_EQ(result.exit_code, 0) << result.out << result.err;
  for (const char* line : {"rounds: 3\n", "lost: 0\n", "doubled: 0\n", "stuck: 0\n", "integrity: ok\n"})
    EXPECT_NE(result.out.find(line), std::string::npos) << line << " missing from:\n" << result.out;
}

}  // namespace
}  // namespace atelier
