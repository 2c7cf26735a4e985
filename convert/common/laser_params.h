// Laser settings of the laser kinds (cut, sketch, parquetry, engrave), read strictly from the `[laser]` table (the daemon's config
// section, injected as the `laser` key of a job's parameters).
//
// Keys (default, range):
//   work_area_mm = [400, 400]   bed width (X) and depth (Y), each 1..5000
//   s_max = 1000 (1..100000)     GRBL $30: the S value of full power
//   origin                       refused: jobs are in bed coordinates (X from the bed's left
//                                edge, Y from its front edge) and the driver places them per
//                                job (start_from = bed | origin | here)
//   Machine motion, for the time estimates (GRBL's planner model; set them as the machine's
//   $ settings are):
//   travel_mm_min = 6000 (1..100000)   G0 speed = max rate, GRBL $110/$111
//   acceleration_mm_s2 = 500 (1..100000)   GRBL $120/$121
//   junction_deviation_mm = 0.010 (0.001..1)   GRBL $11
//   tolerance_mm = 0.05 (0.001..1)     largest deviation of flattened curves
//   check_first = false          run the job in GRBL check mode ($C) first (used by the driver)
//   start_from = "bed" | "origin" | "here"   where job (0, 0) lands when it starts (used by
//                                the driver: the bed's front-left corner, work zero G54, or
//                                the head's position)
//   [[laser.layer]]              one per SVG stroke colour, like LightBurn's colour layers:
//     color = "#rrggbb"          required; also "#rgb" and the SVG names black, white, red,
//                                green (#008000), lime, blue, yellow, cyan, magenta, orange,
//                                gray/grey; stored as "#rrggbb" lower case. No duplicates.
//     name = the colour as written
//     mode = "cut" | "engrave"   default cut
//     speed_mm_min = 600 (1..100000), power_pct = 80 (0..100), passes = 1 (1..50),
//     kerf_mm = 0 (0..2)         cut layers: closed shapes are offset by kerf/2
// Without any [[laser.layer]]: black #000000 cut (600 mm/min, 80 %, 1 pass), red #ff0000 cut
// (same), blue #0000ff engrave (3000 mm/min, 20 %).
//
// Errors are ParamError "FILE:LINE: key 'laser.k': ...". Thread-safe (no shared state).
#pragma once

#include <optional>
#include <string>
#include <toml++/toml.h>
#include <vector>

#include "algorithms/laser/plan.h"

namespace atelier {

struct LaserParams {
  laser::Machine machine;
  std::vector<laser::LayerSettings> layers;
  double tolerance_mm = 0.05;
  bool check_first = false;
  std::string start_from = "bed";  // the driver's; conversions ignore it
};

// `table` is the [laser] table itself; `source` names the file for errors without a line.
LaserParams read_laser_params(const toml::table& table, const std::string& source);

// "#rrggbb" (lower case) for "#rrggbb", "#rgb" or a colour name listed above (any case);
// nullopt otherwise.
std::optional<std::string> parse_laser_color(const std::string& text);

// The layer whose colour is `color` ("#rrggbb"), or nullptr.
const laser::LayerSettings* layer_for_color(const LaserParams& params, const std::string& color);

}  // namespace atelier
