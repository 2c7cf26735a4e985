// GRBL 1.1h's motion planner and stepper timing as a model: how long each move of a job takes
// on a real GRBL, so estimates ("time left") and the emulator agree with the machine.
//
// What is modelled (from grbl/planner.c, stepper.c, config.h of GRBL 1.1h):
// - plan_buffer_line: targets rounded to whole steps ($100-$102; the length is that of the
//   step deltas), the block's acceleration and rapid rate limited per axis along its unit
//   vector ($110-$112, $120-$122), the junction speed from junction deviation ($11) and the
//   junction angle, max entry = min(junction speed, this and the previous block's nominal
//   speed), nominal speed at least MINIMUM_FEED_RATE (1 mm/min), empty (zero-step) blocks
//   dropped.
// - planner_recalculate's reverse and forward passes over the blocks in the buffer: 16 slots,
//   15 usable (`planner_blocks`). The last block in the buffer always plans to stop.
// - The stepper's per-block trapezoid (accelerate, cruise, decelerate) from the entry speed
//   to the exit speed the planner gives when the stepper prepares that block.
// Stream model: the host keeps the planner full (a block being prepared sees the next
// planner_blocks-1 blocks), so block i's exit speed comes from blocks i..i+14. A move marked
// `from_rest` starts with an empty planner (GRBL synchronised the buffer before it: M3/M4/M5
// changes, an S change on a line without motion while the laser is on, G4, M0, ...), so the
// move before it ends at rest. Overrides are 100 %. Serial starvation is not modelled.
//
// Pure functions, thread-safe. Units: mm, mm/min (rates), mm/s^2 (settings), seconds.
#pragma once

#include <array>
#include <map>
#include <vector>

namespace atelier::laser {

struct MotionSettings {
  std::array<double, 3> max_rate_mm_min{6000, 6000, 500};  // $110-$112
  std::array<double, 3> accel_mm_s2{500, 500, 100};        // $120-$122
  std::array<double, 3> steps_per_mm{250, 250, 250};       // $100-$102
  double junction_deviation_mm = 0.010;                    // $11
  int planner_blocks = 15;  // usable planner blocks (BLOCK_BUFFER_SIZE 16, one kept free)
};

// Settings from GRBL's `$N=value` numbers ($11, $100-102, $110-112, $120-122); ids not
// given keep MotionSettings' defaults, others are ignored.
MotionSettings motion_settings_from(const std::map<int, double>& dollar);

struct PlannedMove {
  std::array<double, 3> target;  // absolute machine/work mm
  double feed_mm_min = 0;        // G1/G2/G3 feed; ignored when rapid
  bool rapid = false;            // G0: at the block's rapid rate
  bool from_rest = false;        // the planner was emptied before this move (GRBL sync)
};

// The speed profile of one planned block as the stepper runs it (mm/min, mm).
struct BlockProfile {
  double millimeters = 0;
  double entry_mm_min = 0, nominal_mm_min = 0, exit_mm_min = 0;
  double accel_mm_min2 = 0;
  double seconds = 0;
};

// Seconds of each move in order (same length as `moves`; 0 for moves with no steps),
// starting from rest at `start`. Throws std::invalid_argument for non-positive settings.
std::vector<double> move_seconds(const std::vector<PlannedMove>& moves, const MotionSettings&,
                                 std::array<double, 3> start = {});

// The same, with each move's profile (empty moves have millimeters 0).
std::vector<BlockProfile> plan_profiles(const std::vector<PlannedMove>& moves,
                                        const MotionSettings&, std::array<double, 3> start = {});

// The time a trapezoid takes: `mm` at acceleration `accel_mm_min2`, from `entry` to `exit`
// with a cruise at most `nominal` (all mm/min). Entry/exit above what the length allows are
// taken as given (the profile is clamped, never negative).
double trapezoid_seconds(double mm, double entry_mm_min, double nominal_mm_min,
                         double exit_mm_min, double accel_mm_min2);

}  // namespace atelier::laser
