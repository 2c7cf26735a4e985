// The fake clock (base/fake_clock.h): it stands still until moved, wakes sleepers and waiters
// exactly when their deadline is reached, and with auto-advance jumps to a lone waiter's deadline.
#include <gtest/gtest.h>

#include <future>
#include <thread>

#include "base/fake_clock.h"
#include "tests/unit/base/waiter_fixture.h"

namespace atelier {
namespace {

using namespace std::chrono_literals;
using test::Waiter;
using time_point = Clock::time_point;

TEST(FakeClock, StandsStillUntilMovedAndNeverGoesBack) {
  FakeClock clock;
  const time_point t0 = clock.now();
  EXPECT_EQ(t0, FakeClock::kStart);
  EXPECT_EQ(clock.now(), t0);
  clock.advance(250ms);
  EXPECT_EQ(clock.now(), t0 + 250ms);
  clock.advance_to(t0 + 1s);
  EXPECT_EQ(clock.now(), t0 + 1s);
  clock.advance_to(t0);  // earlier: ignored
  EXPECT_EQ(clock.now(), t0 + 1s);
  // A default time_point is long ago, as on a running machine.
  EXPECT_GE(clock.now() - time_point{}, std::chrono::hours(1));
}

TEST(FakeClock, DeadlineAfterSaturatesInsteadOfOverflowing) {
  FakeClock clock;
  EXPECT_EQ(clock.deadline_after(Clock::duration::max()), time_point::max());
  EXPECT_EQ(clock.deadline_after(5ms), clock.now() + 5ms);
}

TEST(FakeClock, SleepingUntilNowOrThePastReturnsAtOnce) {
  FakeClock clock;
  const time_point t0 = clock.now();
  clock.sleep_until(t0);
  clock.sleep_until(t0 - 1s);
  clock.sleep_for(0ms);
  EXPECT_EQ(clock.now(), t0);  // sleeping moved nothing
}

TEST(FakeClock, ASleeperWakesWhenTheClockReachesItsTime) {
  FakeClock clock;
  const time_point t0 = clock.now();
  auto sleeper = std::async(std::launch::async, [&] {
    clock.sleep_until(t0 + 1s);
    return clock.now();
  });
  clock.await_waiters(1);
  EXPECT_EQ(clock.waiters(), 1u);
  clock.advance(400ms);  // not yet
  clock.advance(600ms);
  EXPECT_EQ(sleeper.get(), t0 + 1s);  // returned no earlier than its time (the clock never passed it)
  EXPECT_EQ(clock.waiters(), 0u);
}

TEST(FakeClock, AWaitTimesOutExactlyAtItsDeadline) {
  FakeClock clock;
  const time_point t0 = clock.now();
  Waiter w;
  auto outcome = w.start(clock, t0 + 300ms);
  clock.await_waiters(1);
  clock.advance(300ms);
  const auto o = outcome.get();
  EXPECT_FALSE(o.satisfied);
  EXPECT_EQ(o.at, t0 + 300ms);
}

TEST(FakeClock, AnAdvanceShortOfTheDeadlineLeavesTheWaitToItsNotify) {
  FakeClock clock;
  const time_point t0 = clock.now();
  Waiter w;
  auto outcome = w.start(clock, t0 + 300ms);
  clock.await_waiters(1);
  clock.advance(299ms);
  clock.await_waiters(1);  // still waiting
  w.make_ready();
  const auto o = outcome.get();
  EXPECT_TRUE(o.satisfied);
  EXPECT_EQ(o.at, t0 + 299ms);
}

TEST(FakeClock, ANotifiedWaitReturnsWithoutTimeMoving) {
  FakeClock clock;
  const time_point t0 = clock.now();
  Waiter w;
  auto outcome = w.start(clock, time_point::max());  // no deadline at all
  clock.await_waiters(1);
  w.make_ready();
  const auto o = outcome.get();
  EXPECT_TRUE(o.satisfied);
  EXPECT_EQ(o.at, t0);
}

TEST(FakeClock, AWaitWhoseConditionHoldsDoesNotBlock) {
  FakeClock clock;
  Waiter w;
  w.ready = true;
  std::unique_lock lock(w.mu);
  EXPECT_TRUE(clock.wait_for(w.cv, lock, 10s, [&] { return w.ready; }));
  EXPECT_TRUE(clock.wait_until(w.cv, lock, clock.now() - 1s, [&] { return w.ready; }));  // even past its deadline
  EXPECT_EQ(clock.now(), FakeClock::kStart);
}

TEST(FakeClock, OneAdvanceWakesEveryWaiterItPassesAndOnlyThose) {
  FakeClock clock;
  const time_point t0 = clock.now();
  Waiter early, late;
  auto first = early.start(clock, t0 + 100ms);
  auto second = late.start(clock, t0 + 900ms);
  clock.await_waiters(2);
  clock.advance(500ms);
  const auto o = first.get();
  EXPECT_FALSE(o.satisfied);
  EXPECT_EQ(o.at, t0 + 500ms);
  clock.await_waiters(1);  // the late one still waits
  late.make_ready();
  EXPECT_TRUE(second.get().satisfied);
}

TEST(FakeClock, AutoAdvanceJumpsToALoneWaitersDeadline) {
  FakeClock clock;
  clock.set_auto_advance(true);
  const time_point t0 = clock.now();
  clock.sleep_for(250ms);
  EXPECT_EQ(clock.now(), t0 + 250ms);
  Waiter w;
  std::unique_lock lock(w.mu);
  EXPECT_FALSE(clock.wait_for(w.cv, lock, 2s, [&] { return w.ready; }));
  EXPECT_EQ(clock.now(), t0 + 2250ms);
  // The jump is an advance like any other: it wakes a waiter whose deadline it passes.
  lock.unlock();
  clock.set_auto_advance(false);
  Waiter other;
  auto outcome = other.start(clock, t0 + 3s);
  clock.await_waiters(1);
  clock.set_auto_advance(true);
  clock.sleep_for(5s);
  const auto o = outcome.get();
  EXPECT_FALSE(o.satisfied);
  EXPECT_GE(o.at, t0 + 3s);
  EXPECT_EQ(clock.now(), t0 + 2250ms + 5s);
}

TEST(FakeClock, AutoAdvanceStillBlocksAWaitWithoutDeadlineUntilNotified) {
  FakeClock clock;
  clock.set_auto_advance(true);
  Waiter w;
  auto outcome = w.start(clock, time_point::max());
  clock.await_waiters(1);
  w.make_ready();
  const auto o = outcome.get();
  EXPECT_TRUE(o.satisfied);
  EXPECT_EQ(o.at, FakeClock::kStart);
}

}  // namespace
}  // namespace atelier
