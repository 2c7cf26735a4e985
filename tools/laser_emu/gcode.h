// The G-code parser of the laser emulator: GRBL 1.1h's gc_execute_line() for the subset a
// laser uses, with GRBL's error codes and laser-mode spindle rules. Pure: it turns one
// pre-filtered line (upper case, no spaces or comments, as protocol.c hands it over) into
// the parser's new modal state plus a list of actions for the controller to run in order
// (planner blocks, buffer syncs, spindle changes, dwells, program end).
//
// Supported: G0 G1 G2 G3 (arcs cut into chords as mc_arc() does, $12 tolerance) G4 G10 L2/L20
// G17 G18 G19 G20 G21 G28 G28.1 G30 G30.1 G40 G43.1 G49 G53 G54..G59 G61 G80 G90 G91 G91.1 G92
// G92.1 G93 G94, M0 M1 M2 M30 M3 M4 M5 M8 M9, F S T N X Y Z I J K L R P. Answered error:20 as
// stock 1.1h does: M7 (mist needs ENABLE_M7). Not emulated, answered error:20: G38.x (probing;
// the real one would run a probe move and raise ALARM:4/5).
// Errors (GRBL numbering): 1 expected letter, 2 bad number, 4 negative value, 20 unsupported,
// 21 modal group violation, 22 feed rate not set, 23 non-integer G/M, 24 axis command conflict,
// 25 word repeated, 26 no axis words, 27 line number too big, 28 value word (P) missing,
// 29 G10 P beyond 6, 30 G53 without G0/G1, 31 axis words with G80, 32 no axis words in plane, 33 invalid target,
// 34 arc radius error, 35 no offsets in plane, 36 unused words, 37 G43.1 without exactly Z,
// 38 tool number > 255; for jogs also 16 invalid jog command.
// Units: mm and mm/min inside (G20 input is converted), seconds for dwells.
// Not thread-safe (plain functions over value types).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "tools/laser_emu/settings.h"

namespace atelier::laser_emu {

using Vec3 = std::array<double, 3>;  // X, Y, Z in mm

enum class Spindle { off = 5, cw = 3, ccw = 4 };  // M5, M3 (constant power), M4 (dynamic)

// gc_state: what "$G" reports, plus the parser's idea of the position (the end of the last
// queued motion, machine coordinates).
struct GcState {
  int motion = 0;  // 0, 1, 2, 3 or 80
  int plane = 0;   // 0 = G17 (XY), 1 = G18 (ZX), 2 = G19 (YZ)
  bool inches = false;
  bool incremental = false;
  bool inverse_time = false;  // G93
  int coord_select = 0;       // 0..5 = G54..G59
  Spindle spindle = Spindle::off;
  bool mist = false, flood = false;
  int tool = 0;     // T of the last executed line (gc_block.values.t: 0 when a line has no T)
  double feed = 0;  // mm/min (G93: 1/min of the last block)
  double s = 0;     // programmed spindle speed / laser power
  Vec3 position{};  // machine mm
  Vec3 g92{};       // G92 offset, mm
  double tlo = 0;   // G43.1 tool length offset (Z), mm
  // What GRBL keeps in EEPROM (survives resets; the controller carries it over): G54..G59
  // offsets (0..5), G28 (6) and G30 (7) positions, machine mm.
  std::array<Vec3, 8> coord_data{};

  // Work coordinate offset: WPos = MPos - WCO (G5x offset + G92 + TLO on Z), mm.
  Vec3 wco() const {
    Vec3 w = coord_data[coord_select];
    for (int i = 0; i < 3; ++i) w[i] += g92[i];
    w[2] += tlo;
    return w;
  }

  // "[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]"; F in the units $13 reports (`report_inches`),
  // whatever G20/G21 is, as report_gcode_modes() prints it.
  std::string modes_report(bool report_inches = false) const;
};

struct Action {
  enum class Kind {
    line,          // queue a planner block (after GRBL's soft-limit check)
    sync,          // wait until the planner is empty and motion has stopped
    spindle,       // sync, then set the laser output to (spindle, s)
    dwell,         // sync, then wait `seconds`
    wco_change,    // sync, then report WCO in the next status report (G92, G54..)
    program_end,   // M2/M30: sync, laser off, "[MSG:Pgm End]"
    pause,         // M0: sync, then feed hold
  };
  Kind kind = Kind::sync;
  Vec3 target{};          // line: machine mm
  double feed = 0;        // line: mm/min (for inverse_time: 1/min, the block's duration is 1/feed)
  bool rapid = false;     // line: G0
  bool inverse_time = false;
  Spindle spindle = Spindle::off;  // line, spindle
  double s = 0;           // line: laser power for this block (0 for G0: laser disabled); spindle
  double seconds = 0;     // dwell
};

struct LineResult {
  int status = 0;  // 0 = ok, else GRBL error code
  std::vector<Action> actions;
};

// Parses and "executes" one line: on success `state` is updated and the actions are returned;
// on error `state` is unchanged and no action is returned (GRBL rejects the whole line).
// `jog`: the words of a "$J=" line (after the "="), checked in gcode.c's order with
// GC_PARSER_JOG_MOTION: G1/G94 enforced, F required (22), S/T unused words (36), commands other
// than G20/G21 G90/G91 G53 invalid (16), each where gcode.c checks it. A jog leaves `state`
// untouched and returns one line action (with the parser's spindle and S: M3 stays on).
LineResult execute_gcode_line(const std::string& line, GcState& state, const Settings& settings, bool jog = false);

// GRBL's read_float(): optional sign, digits, at most one '.', no exponent. Advances `pos`.
// As in GRBL, only the first 8 digits are significant (further integer digits scale by 10,
// further decimals are dropped), so no digit string overflows. A value beyond a float's range
// (|v| > 3.4e38, where GRBL's float would be infinite) is refused: false, GRBL's error:2.
//
// Numbers that would be cast to an integer are range-checked first (never undefined
// behaviour): a G or M command number above 255 (GRBL keeps it in a uint8) is error:20,
// unsupported command; T above 255 error:38; N of 10^7 or more error:27; an arc that would
// need more chords than GRBL's uint16 segment counter holds (65535) error:33, invalid target.
bool read_grbl_float(const std::string& line, size_t& pos, double& value);

}  // namespace atelier::laser_emu
