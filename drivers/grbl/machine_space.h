// Where a job goes on the machine (issue 20, contracts B and C): the machine's own space as
// GRBL 1.1h's soft limits see it, the lines that place a job's (0,0) per "start from" mode,
// and the check that the placed job fits that space before anything is sent.
// Jobs are written in bed coordinates: X mm from the bed's left edge, Y mm from its front
// edge, (0,0) the front-left corner. Units: mm (machine coordinates = MPos). Pure, thread-safe.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/grbl/messages.h"
#include "drivers/grbl/program.h"
#include "drivers/grbl/session.h"

namespace atelier::grbl {

// bed: job (0,0) at the bed's front-left corner (G92 before the job, G92.1 after; LightBurn's
// "Absolute Coords"). origin: at work zero G54 as the operator set it (no G92; "User
// Origin"). here: at the head's position when the job starts (G92 X0 Y0; "Current Position").
enum class StartFrom { bed, origin, here };
std::optional<StartFrom> parse_start_from(std::string_view name);  // "bed" | "origin" | "here"
const char* start_from_name(StartFrom from);

struct AxisRange {
  double min = 0, max = 0;  // machine mm
};

// X, Y, Z. homed_space: homing is on ($22=1), so the ranges are where GRBL's soft limits put
// the axes after $H (stock 1.1h: [-$13x, 0]; HOMING_FORCE_SET_ORIGIN, OPT letter 'Z': an axis
// homed towards negative ($23 bit set) is [0, $13x]). Homing off: the power-up position is
// machine 0 and taken as the bed's front-left corner, so each axis is [0, $13x].
struct MachineSpace {
  std::array<AxisRange, 3> axis;
  bool homed_space = false;
};
MachineSpace machine_space(const MachineInfo& info);

// The bed's front-left corner in machine mm: (min X, min Y) of the space.
std::array<double, 2> bed_corner(const MachineSpace& s);

// Line(s) to send before the job so job (0,0) lands where `from` says: "G92X..Y.." (bed,
// here) or nothing (origin). `now` is a status whose x, y, z are machine coordinates; `wco`
// the work offset now. After a job placed with G92 the caller sends kClearPlacement.
std::vector<std::string> placement_lines(StartFrom from, const MachineSpace& s, const Status& now,
                                         const std::array<double, 3>& wco);
inline constexpr const char* kClearPlacement = "G92.1";

// Machine mm added to a job coordinate once placed per `from` (X, Y).
std::array<double, 2> placement_offset(StartFrom from, const MachineSpace& s, const Status& now,
                                       const std::array<double, 3>& wco);

// "" when the job fits (or soft limits are off, $20=0: GRBL would not check either; an axis
// whose $13x is 0 is not checked), else the
// reason, naming the axis, the job's range in machine space and the machine's range, e.g.
// "the job spans X 10.0..120.0 mm in the machine's space but the machine reaches X -400.0..0.0
// mm (start from origin: work zero is at X 10.0 Y 5.0 in machine space)".
std::string check_fits(const Bounds& job, StartFrom from, const MachineSpace& s, const MachineInfo& info,
                       const Status& now, const std::array<double, 3>& wco);

}  // namespace atelier::grbl
