// Fault injection and knitter behaviour for the knitting-machine emulator
// (atelier-knit-emu --fault SPEC). Pure parsing; no I/O. Not thread-safe (plain value type).
//
// SPEC syntax (each --fault takes one; repeat the option for several). Rows are counted from 1
// over the emulator's life, across resets and replugs.
//   drop-after-row=N      after row N is recorded the link is unplugged: pty closed, link removed
//   drop-after-row=N:M    the same, and the link comes back after M ms (default 1000)
//   replug-ms=M           replug delay on its own (same meaning as the :M suffix)
//   corrupt=F             each byte the emulator RECEIVES is corrupted with probability F in [0,1]
//   seed=S                seed of the corruption generator (default 1): same seed, same bytes hit
//   corrupt-line=N        the Nth cnfLine received (counted over the emulator's life) arrives with
//                         one needle byte broken (the byte holding the first needle of the working
//                         range, all 8 bits flipped), so its CRC fails: as firmware 1.0 does, the
//                         garbled needles stay in the buffer and no reqLine follows
//   bad-escape-after-row=N  after row N is recorded, the next byte received is taken as SLIP ESC
//                         followed by an invalid byte: the firmware hangs (answers nothing, the
//                         carriage selects nothing) until it is reset (DTR, replug)
//   silent-after-row=N    after row N is recorded the firmware answers nothing any more, across
//                         resets too (a dead board)
//   api=V                 cnfInfo reports API version V (e.g. 5) instead of 6
//   delay-ms=N            every reply leaves the firmware N ms after the event that caused it
//   no-dtr-reset          the board does not reset when a host opens the port (its auto-reset is
//                         cut or disabled): the firmware keeps its state (e.g. knit) and the next
//                         host finds it there
// The simulated knitter (who pushes the carriage; tools/knit_emu/firmware.h):
//   knitter-pause-ms=M    how soon after the beep of an accepted line the knitter pushes the next
//                         pass (default 10)
//   knitter-patience-ms=M how long a knitter who hears no beep waits before pushing anyway
//                         (default 2 x row-ms); the pass then knits the buffer as it is. A job's
//                         first pass always waits for a beep; after two passes in a row with no
//                         beep the knitter waits for one
//   impatient-knitter     the knitter pushes knitter-pause-ms after the end of each pass without
//                         waiting for any beep: a slow host means the old buffer is knitted
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
  std::optional<int> corrupt_line;          // 1-based cnfLine count over the emulator's life
  std::optional<int> bad_escape_after_row;  // row count over the emulator's life
  std::optional<int> silent_after_row;
  uint8_t api = 6;
  int64_t delay_ms = 0;
  bool dtr_reset = true;  // false: no-dtr-reset
  // The knitter.
  int64_t knitter_pause_ms = 10;
  std::optional<int64_t> knitter_patience_ms;  // empty: 2 x row_ms
  bool impatient_knitter = false;
};

// Applies one SPEC to `faults`. Returns an empty string on success, else a message naming the
// spec and the problem (e.g. "--fault corrupt=2: fraction must be in [0,1]").
std::string apply_fault(const std::string& spec, Faults& faults);

}  // namespace atelier::knit_emu
