// A laser job: layers of vector paths -> ordered, kerf-compensated toolpaths -> GRBL 1.1
// G-code (laser mode, $32=1), with statistics and a time estimate (GRBL's planner model).
//
// Coordinates. Input paths are in "design" coordinates as drawn in an SVG: x to the right,
// y DOWN, origin at the top-left (rear-left) corner of the bed, in mm. The G-code is always in
// bed coordinates: X = x (mm from the bed's left edge), Y = height - y (mm from its FRONT
// edge), so (0, 0) is the bed's front-left corner and the work area is [0, width] x
// [0, height] in both. Where the job lands on the machine (its homing corner, negative
// machine space, a user origin or the head's position) is the driver's business at run time
// (`start_from` = bed | origin | here), not the program's. The head is assumed to start at
// bed (0, 0).
//
// G-code. Header comments the driver reads (`; atelier laser job`, `; s_max=N`,
// `; bounds=minX,minY,maxX,maxY` in bed mm over every beam-on point), `G21 G90`, then per
// layer a comment and `M4 S<power>` (dynamic power: the beam follows the actual speed and is
// off whenever the head stops), `G0` travel (beam off in laser mode), `G1` burns with F only
// when it changes; `M5` last. Numbers have at most 3 decimals; lines are <= 70 characters.
//
// Order. Engrave layers before cut layers, otherwise the given order. Within a layer, paths
// inside a closed path are burned before it (a piece must not drop before its holes are cut)
// and the next path is the nearest allowed one (closed paths start at their nearest vertex,
// open paths may run backwards). Each path is burned `passes` times in a row (open paths
// alternate direction) before the head moves on.
//
// Pure (no I/O, clocks or logging); thread-safe.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "algorithms/laser/geometry.h"
#include "base/error.h"

namespace atelier::laser {

enum class Mode { cut, engrave };
const char* mode_name(Mode mode);

struct LayerSettings {
  std::string name;
  std::string color;  // "#rrggbb", lower case
  Mode mode = Mode::cut;
  double speed_mm_min = 600;
  double power_pct = 80;  // of s_max
  int passes = 1;
  double kerf_mm = 0;     // cut layers, closed paths only
};

struct Layer {
  LayerSettings settings;
  std::vector<Path> paths;  // design coordinates (see above)
};

struct Machine {
  double width_mm = 400, height_mm = 400;
  double s_max = 1000;          // GRBL $30: S at full power
  double travel_mm_min = 6000;  // G0 speed (GRBL's max rate $110/$111), for the time estimate
  double accel_mm_s2 = 500;     // GRBL $120/$121, for the time estimate
  double junction_deviation_mm = 0.010;  // GRBL $11, for the time estimate
};

struct LayerStats {
  std::string name;
  Mode mode = Mode::cut;
  size_t paths = 0;         // after kerf offset (a split hole counts twice)
  double length_mm = 0;     // burned per pass
  int passes = 1;
  double time_s = 0;        // burns of every pass plus the travel to each path (planner model)
  size_t vanished_holes = 0;  // holes smaller than the kerf, not cut
};

struct PlannedLayer {
  LayerSettings settings;
  std::vector<Path> paths;  // bed coordinates, burn order, kerf applied; one pass each
};

struct Job {
  std::string gcode;
  Bounds bounds;                     // bed coordinates of every beam-on point
  std::vector<LayerStats> layers;    // non-empty layers, in burn order
  std::vector<PlannedLayer> toolpaths;  // parallel to `layers`
  double cut_length_mm = 0;          // burned, all passes
  double engrave_length_mm = 0;      // burned, all passes
  double travel_length_mm = 0;       // G0, from bed (0, 0) on
  double estimated_s = 0;            // GRBL's planner model (motion_planner.h) with the Machine's
                                     // rate, acceleration and junction deviation
};

class PlanError : public BadInput {
 public:
  using BadInput::BadInput;
};

// Throws PlanError when nothing is left to burn, when settings are unusable (speed <= 0,
// passes < 1, power outside 0..100, machine size or s_max <= 0), or when any point lies
// outside the work area ("the job spans X a..b mm x Y c..d mm, outside the W x H mm work
// area ..."), so that nothing is ever sent for such a job.
Job plan_job(const std::vector<Layer>& layers, const Machine& machine);

// Several jobs as one program, run one after another, e.g. one veneer sheet each: the
// operator swaps the material while GRBL waits in a program pause. One header (`; s_max=`,
// `; bounds=` = the union of the jobs' bounds, `G21 G90`), then per job: the comment lines
// `notes[i]` (each written as "; <note>"), for every job but the first an `M0` (program pause:
// GRBL holds until cycle start), and the job's moves as plan_job wrote them (each ends with
// M5, so the beam is off while paused). Statistics are summed, layers and toolpaths
// concatenated in order. Throws PlanError for no jobs or notes.size() != jobs.size().
Job join_jobs(const std::vector<Job>& jobs, const std::vector<std::vector<std::string>>& notes,
              const Machine& machine);

// "12.5", "-3", "0.001": at most 3 decimals, trailing zeros stripped, never "-0".
std::string format_number(double value);

}  // namespace atelier::laser
