// The hot folder's poll mode (network shares, where inotify sees nothing): a file counts as
// complete once its size and mtime have stood still for settle_ms, measured on the folder's
// clock - a FakeClock here, so the settle time passes when the test says. And inotify mode:
// FIFOs and hard links (no close-after-write), 2000 files at once, a queue overflow.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <fstream>
#include <set>
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

// inotify mode: what arrives without a close-after-write is reported when it appears.
namespace atelier {
namespace {

std::set<fs::path> collect_all(HotFolder& folder) {
  std::set<fs::path> out;
  for (const auto& p : folder.collect()) out.insert(p);
  return out;
}

TEST(HotFolderInotify, AFifoAndAHardLinkAreReportedWhenTheyAppear) {
  test::TempDir tmp;
  const SpoolLayout layout{tmp.path() / "spool"};
  fs::create_directories(layout.incoming("knit"));
  HotFolder folder(layout, WatchMode::inotify, 500);

  const fs::path fifo = layout.incoming("knit") / "pipe.png";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0);
  const fs::path original = tmp.path() / "cat.png";
  test::write_file(original, "picture");
  const fs::path link = layout.incoming("knit") / "cat.png";
  fs::create_hard_link(original, link);
  EXPECT_EQ(collect_all(folder), (std::set<fs::path>{fifo, link}));
}

TEST(HotFolderInotify, AFileStillBeingWrittenWaitsForItsClose) {
  test::TempDir tmp;
  const SpoolLayout layout{tmp.path() / "spool"};
  fs::create_directories(layout.incoming("knit"));
  HotFolder folder(layout, WatchMode::inotify, 500);
  const fs::path file = layout.incoming("knit") / "slow.png";
  {
    std::ofstream out(file);
    out << "half" << std::flush;
    EXPECT_TRUE(folder.collect().empty()) << "created and open: not complete yet";
  }
  EXPECT_EQ(folder.collect(), std::vector<fs::path>{file});
}

TEST(HotFolderInotify, TwoThousandFilesDroppedAtOnceAreEachReported) {
  test::TempDir tmp;
  const SpoolLayout layout{tmp.path() / "spool"};
  fs::create_directories(layout.incoming("knit"));
  HotFolder folder(layout, WatchMode::inotify, 500);
  std::set<fs::path> dropped;
  for (int i = 0; i < 2000; ++i) {
    const fs::path f = layout.incoming("knit") / ("f" + std::to_string(i) + ".png");
    test::write_file(f, "x");
    dropped.insert(f);
  }
  EXPECT_EQ(collect_all(folder), dropped);
}

TEST(HotFolderInotify, AQueueOverflowRescansAndLosesNothing) {
  long max_events = 16384;
  std::ifstream("/proc/sys/fs/inotify/max_queued_events") >> max_events;
  if (max_events > 200000) GTEST_SKIP() << "max_queued_events " << max_events << ": too many files to overflow";
  test::TempDir tmp;
  const SpoolLayout layout{tmp.path() / "spool"};
  fs::create_directories(layout.incoming("knit"));
  HotFolder folder(layout, WatchMode::inotify, 500);
  // Each file written in place makes two events (create, close-after-write).
  std::set<fs::path> dropped;
  for (long i = 0; i < max_events / 2 + 500; ++i) {
    const fs::path f = layout.incoming("knit") / ("f" + std::to_string(i) + ".png");
    test::write_file(f, "x");
    dropped.insert(f);
  }
  std::set<fs::path> seen;
  for (int i = 0; i < 3; ++i)
    for (const auto& p : folder.collect()) seen.insert(p);
  EXPECT_EQ(seen, dropped);
}

}  // namespace
}  // namespace atelier
