// The real clock (base/clock.h): real_clock() is steady_clock and its sleeps and waits end.
#include <gtest/gtest.h>

#include "base/clock.h"
#include "tests/unit/base/waiter_fixture.h"

namespace atelier {
namespace {

using namespace std::chrono_literals;
using test::Waiter;
using time_point = Clock::time_point;

// The real clock itself: the only test here that waits on real time (a few milliseconds).
TEST(RealClock, IsSteadyClockAndItsWaitsEnd) {
  Clock& clock = real_clock();
  EXPECT_EQ(&clock, &real_clock());
  const time_point before = std::chrono::steady_clock::now();
  const time_point t = clock.now();
  EXPECT_GE(t, before);
  EXPECT_LE(t, std::chrono::steady_clock::now());
  clock.sleep_for(2ms);
  EXPECT_GE(clock.now(), t + 2ms);

  Waiter w;
  std::unique_lock lock(w.mu);
  const time_point deadline = clock.now() + 2ms;
  EXPECT_FALSE(clock.wait_until(w.cv, lock, deadline, [&] { return w.ready; }));
  EXPECT_GE(clock.now(), deadline);
  lock.unlock();
  auto outcome = w.start(clock, time_point::max());  // no deadline: ends only by its notify
  w.make_ready();
  EXPECT_TRUE(outcome.get().satisfied);
}

}  // namespace
}  // namespace atelier
