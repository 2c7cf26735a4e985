#include "base/fake_clock.h"

#include <algorithm>

namespace atelier {
namespace {

// The caller's lock and the clock's, taken and released together by condition_variable_any:
// it releases both only once it is waiting, so a notify from advance_to() (under the clock's
// mutex) cannot slip between the waiter's last look at the time and its going to sleep.
struct BothLocks {
  std::unique_lock<std::mutex>& theirs;
  std::unique_lock<std::mutex>& ours;
  void lock() {
    theirs.lock();  // same order as on entry to wait_until()
    ours.lock();
  }
  void unlock() {
    ours.unlock();
    theirs.unlock();
  }
};

}  // namespace

FakeClock::FakeClock(time_point start) : now_(start.time_since_epoch().count()) {}

Clock::time_point FakeClock::now() const { return time_point(duration(now_.load())); }

void FakeClock::advance_to(time_point t) {
  std::lock_guard lock(mu_);
  advance_locked(t);
}

void FakeClock::advance_locked(time_point t) {
  if (t <= now()) return;
  now_.store(t.time_since_epoch().count());
  for (Waiter* w : waiters_)
    if (w->deadline <= t) w->cv->notify_all();
  sleepers_.notify_all();
}

void FakeClock::set_auto_advance(bool on) {
  std::lock_guard lock(mu_);
  auto_advance_ = on;
}

size_t FakeClock::waiters() const {
  std::lock_guard lock(mu_);
  return blocked_;
}

void FakeClock::await_waiters(size_t n) const {
  std::unique_lock lock(mu_);
  blocked_changed_.wait(lock, [&] { return blocked_ >= n; });
}

void FakeClock::sleep_until(time_point t) {
  std::unique_lock lock(mu_);
  while (now() < t) {
    if (auto_advance_ && t != time_point::max()) {
      advance_locked(t);
      break;
    }
    ++blocked_;
    blocked_changed_.notify_all();
    sleepers_.wait(lock);
    --blocked_;
  }
}

bool FakeClock::wait_until(std::condition_variable_any& cv, std::unique_lock<std::mutex>& lock, time_point deadline,
                           const std::function<bool()>& pred) {
  std::unique_lock ours(mu_);
  Waiter self{&cv, deadline};
  waiters_.push_back(&self);
  bool satisfied = false;
  for (;;) {
    // pred() runs without the clock's mutex, so it may read the clock (or anything else).
    // The caller's lock stays held from here until the wait below releases both.
    ours.unlock();
    satisfied = pred();
    ours.lock();
    if (satisfied || now() >= deadline) break;
    if (auto_advance_ && deadline != time_point::max()) {
      advance_locked(deadline);
      continue;  // one more look at pred(): the time it reaches may be what it waits for
    }
    ++blocked_;
    blocked_changed_.notify_all();
    BothLocks both{lock, ours};
    cv.wait(both);
    --blocked_;
  }
  waiters_.erase(std::find(waiters_.begin(), waiters_.end(), &self));
  return satisfied;
}

}  // namespace atelier
