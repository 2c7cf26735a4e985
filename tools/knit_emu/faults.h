// Fault injection for the knitting-machine emulator (atelier-knit-emu --fault SPEC).
// Pure parsing; no I/O. Not thread-safe (plain value type).
//
// SPEC syntax (each --fault takes one; repeat the option for several):
//   drop-after-row=N      after row N is recorded (rows counted from 1 over the emulator's
//                         life, across replugs) the link is unplugged: pty closed, link removed
//   drop-after-row=N:M    the same, and the link comes back after M ms (default 1000)
//   replug-ms=M           replug delay on its own (same meaning as the :M suffix)
//   corrupt=F             each byte the emulator RECEIVES is corrupted with probability F in [0,1]
//   seed=S                seed of the corruption generator (default 1): same seed, same bytes hit
//   silent-after-row=N    after row N is recorded the firmware answers nothing any more
//   api=V                 cnfInfo reports API version V (e.g. 5) instead of 6
//   delay-ms=N            every reply leaves the firmware N ms after the event that caused it
//   no-dtr-reset          the board does not reset when DTR drops (its auto-reset is cut or
//                         disabled): the firmware keeps its state (e.g. knit) when the host
//                         closes the port or dies, and the next host finds it there
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace atelier::knit_emu {

struct Faults {
  std::optional<int> drop_after_row;
  int64_t replug_ms = 1000;
  double corrupt = 0.0;  // probability per received byte
  uint64_t seed = 1;
  std::optional<int> silent_after_row;
  uint8_t api = 6;
  int64_t delay_ms = 0;
  bool dtr_reset = true;  // false: no-dtr-reset
};

// Applies one SPEC to `faults`. Returns an empty string on success, else a message naming the
// spec and the problem (e.g. "--fault corrupt=2: fraction must be in [0,1]").
std::string apply_fault(const std::string& spec, Faults& faults);

}  // namespace atelier::knit_emu
