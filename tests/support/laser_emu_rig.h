// Test helpers for the laser emulator: a scripted host around the pure GRBL controller model,
// on a virtual microsecond clock (no sleeps); and the model as the far end of a simulated link
// (EmulatedLaserPeer), so a grbl::Session or a LaserDevice talks to it on a FakeClock; that
// peer can restart on a reopened port as an Uno does (reopened()).
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "base/clock.h"
#include "drivers/simulated_transport.h"
#include "tools/laser_emu/controller.h"

namespace atelier::laser_emu::testing {

struct Rig {
  explicit Rig(ControllerOptions o = {}) : ctl(o, record, 0) {}

  void send(const std::string& bytes) { ctl.host_write(bytes, t); }
  // Advances the clock by `us`, collecting output.
  void run(int64_t us) {
    t += us;
    ctl.advance_to(t);
    out += ctl.take_output();
  }
  // Runs in 100 us steps until the output contains `text` (or `max_us` passes).
  bool run_until(const std::string& text, int64_t max_us = 2'000'000) {
    for (int64_t waited = 0; out.find(text) == std::string::npos; waited += 100) {
      if (waited >= max_us) return false;
      run(100);
    }
    return true;
  }
  // Everything output so far, cleared.
  std::string take() {
    std::string s;
    s.swap(out);
    return s;
  }
  // Sends `line` + "\n" and returns the output up to and including its ok/error.
  std::string exchange(const std::string& line, int64_t max_us = 2'000'000) {
    send(line + "\n");
    for (int64_t waited = 0; waited <= max_us; waited += 100) {
      size_t end = std::string::npos;
      const auto ok = out.find("ok\r\n");
      if (ok != std::string::npos) end = ok + 4;
      const auto err = out.find("error:");
      if (err != std::string::npos) {
        const auto eol = out.find("\r\n", err);
        if (eol != std::string::npos && eol + 2 < end) end = eol + 2;
      }
      if (end != std::string::npos) {
        std::string r = out.substr(0, end);
        out.erase(0, end);
        return r;
      }
      run(100);
    }
    return "TIMEOUT:" + take();
  }
  // Skips the power-on banner.
  void boot() {
    run_until("help]\r\n");
    take();
  }

  Record record;
  Controller ctl;
  int64_t t = 0;
  std::string out;
};

// The controller model behind a SimulatedTransport, on the link's fake clock (microseconds
// since the peer was made). Keeps every byte the host wrote (`received()`), so a test sees
// what was sent. Thread-safe: the test thread may look while a device's worker talks to it.
class EmulatedLaserPeer : public SimulatedPeer {
 public:
  EmulatedLaserPeer(Clock::time_point now, ControllerOptions o = {}) : epoch_(now), ctl_(o, record_, 0) {}

  std::string received() const {
    std::lock_guard lock(mu_);
    return received_;
  }
  Vec3 position() const {
    std::lock_guard lock(mu_);
    return ctl_.position();
  }
  std::string state() const {
    std::lock_guard lock(mu_);
    return ctl_.state_name();
  }
  std::vector<Segment> segments() const {
    std::lock_guard lock(mu_);
    return record_.segments;
  }
  // The host closed the port and opened it again at `now`: an Uno's DTR auto-reset restarts
  // the board (position, parser modes and an alarm lock gone; Controller::hangup), and the
  // restarted board's banner follows.
  void reopened(Clock::time_point now) {
    std::lock_guard lock(mu_);
    ctl_.hangup(us(now));
    ctl_.host_connected(us(now));
  }

  void receive(const uint8_t* data, size_t size, Clock::time_point now) override {
    std::lock_guard lock(mu_);
    received_.append(reinterpret_cast<const char*>(data), size);
    ctl_.host_write(std::string_view(reinterpret_cast<const char*>(data), size), us(now));
    ctl_.advance_to(us(now));
  }
  std::vector<uint8_t> take_output(Clock::time_point now) override {
    std::lock_guard lock(mu_);
    ctl_.advance_to(us(now));
    const std::string out = ctl_.take_output();
    return {out.begin(), out.end()};
  }
  std::optional<Clock::time_point> next_event() const override {
    std::lock_guard lock(mu_);
    const auto next = ctl_.next_event_us();
    if (!next) return std::nullopt;
    return epoch_ + std::chrono::microseconds(*next);
  }

 private:
  int64_t us(Clock::time_point t) const {
    return std::chrono::duration_cast<std::chrono::microseconds>(t - epoch_).count();
  }

  const Clock::time_point epoch_;
  mutable std::mutex mu_;
  Record record_;
  Controller ctl_;
  std::string received_;
};

}  // namespace atelier::laser_emu::testing
