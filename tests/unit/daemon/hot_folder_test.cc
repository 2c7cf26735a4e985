// The hot folder's poll mode (network shares, where inotify sees nothing): a file counts as
// complete once its size and mtime have stood still for settle_ms, measured on the folder's
// clock - a FakeClock here, so the settle time passes when the test says.
#include <gtest/gtest.h>

#include <fstream>
#include <vector>

#include "base/fake_clock.h"
#include "daemon/hot_folder.h"
#include "tests/e2e/daemon_harness.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

TEST(HotFolderPoll, AFileIsReportedOnceItHasStoodStillForTheSettleTime) {
  test::TempDir tmp;
  const SpoolLayout layout{tmp.path() / "spool"};
  fs::create_directories(layout.incoming("knit"));
  FakeClock clock;
  HotFolder folder(layout, WatchMode::poll, 200, clock);
  EXPECT_EQ(folder.fd(), -1);

  const fs::path file = layout.incoming("knit") / "slow.png";
  test::write_file(file, "the first half");
  EXPECT_TRUE(folder.collect().empty());  // just seen
  clock.advance(199ms);
  EXPECT_TRUE(folder.collect().empty());  // not settled yet

  // Still being written: the settle time starts again from the change.
  std::ofstream(file, std::ios::app) << " and the second half";
  EXPECT_TRUE(folder.collect().empty());
  clock.advance(199ms);
  EXPECT_TRUE(folder.collect().empty());
  clock.advance(1ms);
  EXPECT_EQ(folder.collect(), std::vector<fs::path>{file});

  clock.advance(1s);
  EXPECT_TRUE(folder.collect().empty());  // reported once only
}

}  // namespace
}  // namespace atelier
