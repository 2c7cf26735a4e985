// The daemon's pick-up loop (daemon/pickup.h): a pick-up that failed for a transient reason
// is retried with a doubling back-off (1 s up to 30 s, on a FakeClock) until it succeeds or
// the file vanishes; a lasting failure is not retried. The failures are injected through the
// JobService's claim hook, plus one real "Too many open files" in a forked child.
#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <system_error>
#include <vector>

#include "base/fake_clock.h"
#include "daemon/pickup.h"
#include "tests/e2e/daemon_harness.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

struct Loop {
  test::TempDir tmp;
  SpoolLayout layout{tmp.path() / "spool"};
  Store store{tmp.path() / "jobs.sqlite"};
  JobService jobs{store, layout, nullptr};
  FakeClock clock;
  std::vector<int64_t> queued;
  std::unique_ptr<HotFolder> folder;
  std::unique_ptr<Pickup> pickup;
  int failures_left = 0;
  int tries = 0;
  int error = EMFILE;

  Loop() {
    jobs.ensure_layout();
    folder = std::make_unique<HotFolder>(layout, WatchMode::inotify, 500, clock);
    pickup = std::make_unique<Pickup>(*folder, jobs, [this](int64_t id) { queued.push_back(id); }, clock);
    jobs.set_claim_hook([this](const std::string& step) {
      if (step != "claimed") return;
      ++tries;
      if (failures_left > 0) {
        --failures_left;
        throw std::system_error(error, std::generic_category(), "open");
      }
    });
  }
};

TEST(Pickup, ATransientFailureIsRetriedWithADoublingBackOffUntilItSucceeds) {
  Loop l;
  l.failures_left = 3;
  const fs::path file = l.layout.incoming("knit") / "cat.png";
  test::write_file(file, "picture");
  l.pickup->step();
  EXPECT_EQ(l.tries, 1);
  EXPECT_TRUE(l.queued.empty());
  EXPECT_TRUE(fs::exists(file)) << "left in incoming/";
  EXPECT_EQ(l.pickup->next_retry_in(), Clock::duration(1s));

  for (auto wait : {1s, 2s, 4s}) {
    l.clock.advance(wait - 1ms);
    l.pickup->step();
    const int before = l.tries;
    EXPECT_EQ(l.pickup->next_retry_in(), Clock::duration(1ms)) << "not before its time";
    l.clock.advance(1ms);
    l.pickup->step();
    EXPECT_EQ(l.tries, before + 1);
  }
  EXPECT_EQ(l.tries, 4);
  ASSERT_EQ(l.queued.size(), 1u);
  EXPECT_EQ(l.store.get(l.queued[0])->name, "cat.png");
  EXPECT_EQ(l.pickup->waiting_retries(), 0u);
  EXPECT_EQ(l.pickup->next_retry_in(), std::nullopt);
}

TEST(Pickup, TheBackOffStopsGrowingAtThirtySeconds) {
  Loop l;
  l.failures_left = 100;
  test::write_file(l.layout.incoming("knit") / "cat.png", "picture");
  l.pickup->step();
  for (int i = 0; i < 8; ++i) {
    l.clock.advance(*l.pickup->next_retry_in());
    l.pickup->step();
  }
  EXPECT_EQ(l.pickup->next_retry_in(), Clock::duration(30s));
}

TEST(Pickup, ARetryEndsWhenTheFileVanishesAndALastingFailureIsNotRetried) {
  Loop l;
  l.failures_left = 1;
  const fs::path file = l.layout.incoming("knit") / "cat.png";
  test::write_file(file, "picture");
  l.pickup->step();
  ASSERT_EQ(l.pickup->waiting_retries(), 1u);
  fs::remove(file);
  l.clock.advance(1s);
  l.pickup->step();
  EXPECT_EQ(l.pickup->waiting_retries(), 0u);
  EXPECT_TRUE(l.queued.empty());

  l.error = EACCES;
  l.failures_left = 1;
  test::write_file(l.layout.incoming("knit") / "dog.png", "picture");
  l.pickup->step();
  EXPECT_EQ(l.pickup->waiting_retries(), 0u) << "permission denied does not pass by waiting";
}

// A real EMFILE: in a child process whose descriptors are used up.
TEST(Pickup, TooManyOpenFilesLeavesTheFileAndATryAfterwardsClaimsIt) {
  test::TempDir tmp;
  const SpoolLayout layout{tmp.path() / "spool"};
  test::write_file(tmp.path() / "cat.png", "picture");
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    int code = 0;
    try {
      Store store{tmp.path() / "jobs.sqlite"};
      JobService jobs{store, layout, nullptr};
      jobs.ensure_layout();
      fs::rename(tmp.path() / "cat.png", layout.incoming("knit") / "cat.png");
      store.reserve_id();  // the store's files are open before the descriptors run out
      struct rlimit lim = {256, 256};
      setrlimit(RLIMIT_NOFILE, &lim);
      std::vector<int> hog;
      for (int fd; (fd = dup(0)) >= 0;) hog.push_back(fd);
      try {
        jobs.claim(layout.incoming("knit") / "cat.png");
        code = 10;  // should have failed
      } catch (const PickupError& e) {
        if (!e.transient()) code = 11;
      }
      for (int fd : hog) ::close(fd);
      if (code == 0 && !fs::exists(layout.incoming("knit") / "cat.png")) code = 12;
      if (code == 0) {
        auto id = jobs.claim(layout.incoming("knit") / "cat.png");
        if (!id || store.get(*id)->state != JobState::queued) code = 13;
      }
    } catch (...) {
      code = 14;
    }
    _exit(code);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0)
      << "10: claimed with no descriptors left, 11: not transient, 12: file not left in incoming/, "
         "13: the later claim failed, 14: exception";
}

}  // namespace
}  // namespace atelier
