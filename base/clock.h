// The clock seam: code that reads the time, sleeps or waits with a deadline does it through a
// Clock, so that tests can run it on a FakeClock (base/fake_clock.h) instead of real time.
// Production code uses real_clock() (std::chrono::steady_clock), which every constructor that
// takes a Clock& defaults to.
//
// Units: Clock::time_point and Clock::duration are std::chrono::steady_clock's (nanoseconds on
// Linux), so existing arithmetic keeps working. Time points of different clocks must not be
// mixed: a deadline is only meaningful on the clock that made it.
// Ownership: whoever takes a Clock& only borrows it; the clock must outlive the user.
// real_clock() lives as long as the program.
// Threading: every member may be called from any thread.
#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>

namespace atelier {

class Clock {
 public:
  using duration = std::chrono::steady_clock::duration;
  using time_point = std::chrono::steady_clock::time_point;

  virtual ~Clock() = default;

  // Never decreases.
  virtual time_point now() const = 0;
  // Returns once now() >= t (at once if it already is).
  virtual void sleep_until(time_point t) = 0;
  void sleep_for(duration d) { sleep_until(deadline_after(d)); }

  // Waits on `cv` until pred() holds or now() >= deadline; returns pred() (false: timed out).
  // `lock` (of the mutex guarding what pred() reads) is held on entry and on return and
  // released while blocked, as with std::condition_variable_any::wait_until. Whoever changes
  // what pred() reads does so under that mutex and then notifies `cv`. pred() is called with
  // `lock` held and must not block. time_point::max() waits without a deadline.
  virtual bool wait_until(std::condition_variable_any& cv, std::unique_lock<std::mutex>& lock,
                          time_point deadline, const std::function<bool()>& pred) = 0;
  bool wait_for(std::condition_variable_any& cv, std::unique_lock<std::mutex>& lock, duration d,
                const std::function<bool()>& pred) {
    return wait_until(cv, lock, deadline_after(d), pred);
  }

  // now() + d, saturated at time_point::max() (so "wait forever" never overflows).
  time_point deadline_after(duration d) const {
    const time_point t = now();
    return d >= time_point::max() - t ? time_point::max() : t + d;
  }
};

// std::chrono::steady_clock. A process-wide singleton, safe to use from any thread.
Clock& real_clock();

}  // namespace atelier
