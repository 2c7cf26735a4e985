// Command-line parsing for atelier-laser-emu: fault specs and the work area. Pure; no I/O.
//
// --fault SPEC (repeatable):
//   drop-at-line=N         after line N is answered (and the answer read or 1 s passed), the pty is
//                          closed and the link removed, like a pulled USB cable; the board loses
//                          power (head stops, beam off). With --replug-ms a fresh controller
//                          appears at the same link after that delay (banner, Idle, position 0).
//   stall-at-line=N        after line N is answered the emulator stops reading and answering;
//                          the port stays open and the controller runs out its planner.
//   alarm-at-line=N[:CODE] raise ALARM:CODE (default 1, hard limit) when line N is taken.
// Lines are numbered from 1 over the emulator's life (across replugs), every line counted:
// G-code, $ commands and empty lines alike (the record's "lines_received").
#pragma once

#include <optional>
#include <string>
#include <utility>

namespace atelier::laser_emu {

struct Faults {
  std::optional<long> drop_at_line;
  std::optional<long> stall_at_line;
  std::optional<long> alarm_at_line;
  int alarm_code = 1;
};

// Applies one SPEC. Returns "" on success, else a message naming the spec and the problem.
std::string apply_fault(const std::string& spec, Faults& faults);

// "400x300" -> {400, 300} (mm, both > 0); empty on a malformed value.
std::optional<std::pair<double, double>> parse_work_area(const std::string& text);

}  // namespace atelier::laser_emu
