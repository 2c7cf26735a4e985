// A Clock for tests: time stands still until something moves it, so no test waits on the real
// clock and every deadline passes exactly when the test lets it.
//
// What moves time (never backwards):
// - advance(d) / advance_to(t), from any thread: a test thread playing the passing of time;
// - a SimulatedTransport (drivers/simulated_transport.h) reading on this clock: a read that
//   would wait moves time to its peer's next event or to the read's deadline, so a session
//   and the machine model it talks to run in lock step on one thread;
// - with auto-advance on (off by default): a sleep_until() or wait_until() that would block
//   moves time to its own deadline at once instead. Meant for code under test that is the only
//   thread waiting on the clock (a single-threaded retry loop, a read that must time out). A
//   wait without a deadline (time_point::max()) still blocks until it is notified.
// Moving time notifies every sleeper and waiter whose deadline it reaches; advance() does not
// wait for them to run. waiters()/await_waiters() tell a test when a thread is blocked on the
// clock, so it can move time only once that thread is waiting (and so know it will wake).
//
// Units: as Clock (steady_clock's time_point and duration). The clock starts a day after
// steady_clock's epoch, so code that takes a default time_point{} for "long ago" sees what it
// sees on a running machine.
// Ownership: a FakeClock is owned by the test; it must outlive everything that uses it, and
// nothing may still be waiting on it when it is destroyed.
// Threading: every member is thread-safe. Lock order: a waiter holds its own mutex, then the
// clock's; so advance() may be called with or without a waiter's mutex held.
#pragma once

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <vector>

#include "base/clock.h"

namespace atelier {

class FakeClock final : public Clock {
 public:
  static constexpr time_point kStart = time_point{} + std::chrono::hours(24);

  explicit FakeClock(time_point start = kStart);
  FakeClock(const FakeClock&) = delete;
  FakeClock& operator=(const FakeClock&) = delete;

  time_point now() const override;
  void sleep_until(time_point t) override;
  bool wait_until(std::condition_variable_any& cv, std::unique_lock<std::mutex>& lock, time_point deadline,
                  const std::function<bool()>& pred) override;

  void advance(duration d) { advance_to(deadline_after(d)); }
  // Moves time to `t`; earlier than now() changes nothing.
  void advance_to(time_point t);

  void set_auto_advance(bool on);

  // Threads blocked in sleep_until() or wait_until() right now (not counting one that has been
  // woken but not yet run).
  size_t waiters() const;
  // Returns once at least `n` threads are blocked on the clock. Any advance after it returns
  // reaches them: a blocked thread's deadline was fixed before it blocked.
  void await_waiters(size_t n) const;

 private:
  struct Waiter {
    std::condition_variable_any* cv;
    time_point deadline;
  };
  void advance_locked(time_point t);  // mu_ held

  mutable std::mutex mu_;
  std::atomic<time_point::rep> now_;  // written under mu_; read without it by now()
  bool auto_advance_ = false;
  std::vector<Waiter*> waiters_;      // threads inside wait_until(), with their deadlines
  std::condition_variable sleepers_;  // threads in sleep_until() (on mu_)
  size_t blocked_ = 0;
  mutable std::condition_variable blocked_changed_;
};

}  // namespace atelier
