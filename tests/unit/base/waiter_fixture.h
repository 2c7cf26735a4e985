// A thread waiting on a Clock for a flag, for the clock tests (fake_clock_test, clock_test).
#pragma once

#include <condition_variable>
#include <future>
#include <mutex>

#include "base/clock.h"

namespace atelier::test {

using time_point = Clock::time_point;

// One thread waiting on `clock` for `ready` (under `mu`), up to `deadline`.
struct Waiter {
  std::mutex mu;
  std::condition_variable_any cv;
  bool ready = false;

  struct Outcome {
    bool satisfied;
    time_point at;  // the clock when the wait returned
  };
  std::future<Outcome> start(Clock& clock, time_point deadline) {
    return std::async(std::launch::async, [this, &clock, deadline] {
      std::unique_lock lock(mu);
      const bool ok = clock.wait_until(cv, lock, deadline, [this] { return ready; });
      return Outcome{ok, clock.now()};
    });
  }
  void make_ready() {
    {
      std::lock_guard lock(mu);
      ready = true;
    }
    cv.notify_all();
  }
};

}  // namespace atelier::test
