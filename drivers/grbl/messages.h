// GRBL 1.1 lines as they arrive from the controller (one line, without its "\r\n"): which
// kind each is, and the fields of status reports, [OPT:] and "$n=value" lines.
// Formats as GRBL 1.1h's report.c prints them. Pure, thread-safe.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

namespace atelier::grbl {

struct Reply {
  enum Kind {
    ok,        // "ok": the oldest line in flight was accepted
    error,     // "error:N": the oldest line in flight was refused; code = N
    alarm,     // "ALARM:N" (pushed, not an answer to a line); code = N
    banner,    // "Grbl 1.1h ['$' for help]": power-up or reset; text = "1.1h"
    status,    // "<Idle|MPos:...>" (answer to '?', never counted as a reply)
    feedback,  // "[MSG:..]", "[GC:..]", "[VER:..]", "[OPT:..]", "[HLP:..]", ...; text = inside the brackets
    setting,   // "$n=value" from $$; code = n, text = value
    startup,   // ">G20G54:ok" (or ":error:N") from a startup line run after reset; text = whole line
    other,     // anything else (noise, $N startup-line listings)
  } kind = other;
  int code = 0;
  std::string text;
};

Reply classify(std::string_view line);

struct Status {
  std::string state;  // Idle Run Hold Jog Alarm Door Check Home Sleep
  int substate = -1;  // Hold:0 (hold complete) / Hold:1 (stopping), Door:0..3; -1 when none
  // Position in mm: machine position (MPos), or WPos+WCO when the report carried both.
  // has_wpos: x, y, z are work coordinates whose offset this report did not carry (GRBL sends
  // WCO only every 10..30 reports); apply_wco() with a remembered offset converts them.
  double x = 0, y = 0, z = 0;
  bool has_wpos = false;
  std::optional<std::array<double, 3>> wco;  // the WCO field of this report, if any
  double feed = 0, spindle = 0;              // FS: (or F:) current feed mm/min and S value
  int planner_free = -1, rx_free = -1;       // Bf: free planner blocks, free receive bytes
  long line = -1;                            // Ln: line number being executed
};

// Parses "<...>"; nullopt when the line is not a status report or has no state.
std::optional<Status> parse_status(std::string_view line);
// Turns work coordinates into machine coordinates with `wco` (no-op when !s.has_wpos).
void apply_wco(Status& s, const std::array<double, 3>& wco);

// "[OPT:VL,15,128]" -> {15 planner blocks, 128 receive-buffer bytes}.
std::optional<std::pair<int, int>> parse_opt(std::string_view line);
// "$30=1000.000" -> {30, 1000.0}.
std::optional<std::pair<int, double>> parse_setting(std::string_view line);

}  // namespace atelier::grbl
