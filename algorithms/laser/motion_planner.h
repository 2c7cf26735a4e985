// GRBL 1.1h's motion planner as a model, for time estimates (drivers/grbl/program.h, the
// laser kinds' report.json) and the laser emulator's motion: how long a run of moves takes on
// a real controller, acceleration included.
//
// What it follows (gnea/grbl 1.1h, planner.c plan_buffer_line / planner_recalculate and
// stepper.c's trapezoids):
// - each move is quantised to whole steps ($100-102) and its unit vector taken from them;
// - its acceleration and rapid rate are the per-axis limits ($120-122 in mm/s^2, $110-112)
//   scaled along the unit vector (limit_value_by_axis_maximum); a feed above the rapid rate is
//   clamped to it;
// - the junction speed with the previous move follows the junction deviation $11 (the
//   "centripetal" formula with sin(theta/2)), capped by both moves' nominal speeds; a move
//   that starts from an empty planner, or after a buffer sync, starts at rest;
// - the planner holds 15 moves (BLOCK_BUFFER_SIZE 16, one slot free). The model assumes the
//   host keeps it full, as a streaming host does: when a move starts, the 14 after it are
//   known and the last of them must be able to stop, so the move's exit speed is what the
//   reverse and forward passes allow over that window;
// - each move runs as a trapezoid: accelerate from its entry speed, cruise at its nominal
//   speed (or less when too short), decelerate to its exit speed.
// Not modelled: the stepper's 8 ms segment granularity, overrides, serial starvation (a link
// slower than the motion empties the planner; the emulator shows that, this model does not).
//
// Units: mm, mm/min for feeds and rates, mm/s^2 for accelerations, seconds for durations.
// Pure, thread-safe (no state).
#pragma once

#include <array>
#include <cstddef>
#include <map>
#include <vector>

namespace atelier::laser {

struct MotionSettings {
  std::array<double, 3> max_rate_mm_min{6000, 6000, 500};  // $110-112
  std::array<double, 3> accel_mm_s2{500, 500, 100};        // $120-122
  std::array<double, 3> steps_per_mm{250, 250, 250};       // $100-102
  double junction_deviation_mm = 0.010;                    // $11
  int planner_blocks = 15;                                 // usable planner blocks (OPT)
};

// From a controller's "$$" settings ($11, $100-102, $110-112, $120-122); missing or
// non-positive values keep the defaults above.
MotionSettings motion_settings_from(const std::map<int, double>& dollar);

struct PlannedMove {
  std::array<double, 3> target{};  // absolute machine-frame mm
  double feed_mm_min = 0;          // programmed feed; ignored for rapids
  bool rapid = false;              // G0: the fastest rate the axes allow along the move
  // A buffer sync comes before this move (spindle state change M3/M4/M5, dwell, an S change
  // on a line without motion in laser mode, ...): the move before it ends at rest.
  bool from_rest = false;
};

// The motion profile of one move as the stepper runs it.
struct MoveProfile {
  double length_mm = 0;
  double entry_mm_min = 0, nominal_mm_min = 0, exit_mm_min = 0;
  double peak_mm_min = 0;       // highest speed reached (<= nominal)
  double accel_mm_s2 = 0;       // along the move
  double accel_mm = 0, decel_mm = 0;  // lengths of the accelerating and decelerating parts
  double seconds = 0;
  // Speed (mm/min) and distance (mm) at time `t` seconds into the move (clamped to the move).
  double speed_at(double t) const;
  double distance_at(double t) const;
};

// One block as plan_buffer_line() fills it.
struct PlannerBlock {
  double length_mm = 0;
  double accel_mm_s2 = 0;      // along the block
  double nominal_mm_min = 0;   // programmed feed (or rapid rate) within the axes' limits
  double max_entry_sqr = 0;    // (mm/s)^2: junction and nominal limits on the entry speed
};

// The part of plan_buffer_line() that depends on the block before: junction speeds and the
// nominal-speed cap. Used move by move by plan_moves() and by the laser emulator's planner.
// Not thread-safe (one planner per user).
class BlockPlanner {
 public:
  // The block for a move of `delta_mm` (already step-quantised, not all zero) at
  // `feed_mm_min` (ignored when `rapid`), with the settings as they are now.
  PlannerBlock add(const MotionSettings& settings, const std::array<double, 3>& delta_mm, double feed_mm_min,
                   bool rapid);
  // The planner emptied (a buffer sync, a stop, the head ran out of blocks): the next block
  // starts at rest.
  void sync() { at_rest_ = true; }

 private:
  std::array<double, 3> prev_unit_{};
  double prev_nominal_ = 0;  // mm/s
  bool at_rest_ = true;
};

// The exit speed (mm/min) planner_recalculate() gives queue[0], entered at `entry_mm_min`,
// when queue[1..count-1] follow it in the planner and the last must be able to stop.
double planned_exit(const PlannerBlock* queue, std::size_t count, double entry_mm_min);

// Trapezoid of a move of `length_mm` from `entry` to `exit` (mm/min) with cruise speed at
// most `nominal` and acceleration `accel_mm_s2`. When entry and exit are not both reachable
// (the planner never asks for that) the exit is lowered/raised to what the length allows.
MoveProfile trapezoid(double length_mm, double entry_mm_min, double nominal_mm_min, double exit_mm_min,
                      double accel_mm_s2);

// Profiles of `moves` in order, starting at rest at `start`; a move with no steps has a
// zero profile (GRBL drops it). Same length as `moves`.
std::vector<MoveProfile> plan_moves(const std::vector<PlannedMove>& moves, const MotionSettings& settings,
                                    std::array<double, 3> start = {});

// Seconds of each move (plan_moves(...)[i].seconds).
std::vector<double> move_seconds(const std::vector<PlannedMove>& moves, const MotionSettings& settings,
                                 std::array<double, 3> start = {});

}  // namespace atelier::laser
