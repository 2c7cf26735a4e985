#include "base/clock.h"

#include <thread>

namespace atelier {
namespace {

class RealClock final : public Clock {
 public:
  time_point now() const override { return std::chrono::steady_clock::now(); }

  void sleep_until(time_point t) override {
    if (t == time_point::max()) {
      // Nothing ever wakes this; it is what the caller asked for (and sleep_until(max) would
      // overflow in the conversion to a timespec).
      for (;;) std::this_thread::sleep_for(std::chrono::hours(24));
    }
    std::this_thread::sleep_until(t);
  }

  bool wait_until(std::condition_variable_any& cv, std::unique_lock<std::mutex>& lock, time_point deadline,
                  const std::function<bool()>& pred) override {
    if (deadline == time_point::max()) {
      cv.wait(lock, pred);
      return true;
    }
    return cv.wait_until(lock, deadline, pred);
  }
};

}  // namespace

Clock& real_clock() {
  static RealClock clock;  // a function-local static: initialised once, thread-safely
  return clock;
}

}  // namespace atelier
