// Test helpers for the laser emulator: a scripted host around the pure GRBL controller model,
// on a virtual microsecond clock (no sleeps).
#pragma once

#include <gtest/gtest.h>

#include <string>

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

}  // namespace atelier::laser_emu::testing
