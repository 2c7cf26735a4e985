// Parameters of `engrave` jobs (a photo burned as a raster, like LightBurn's image mode), read
// strictly from the merged parameter table (config [engrave] < sidecar < --set).
//
// Keys (default, range):
//   dither = "jarvis"      threshold | ordered (8x8 Bayer) | floyd-steinberg | jarvis | stucki
//                          (dots at max power) or greyscale (S per pixel run)
//   dpi = 127 (10..1000)   dots per inch along a scan line (127 = 0.2 mm dots)
//   line_interval_mm = 0.2 (0.01..5)   distance between scan lines
//   spot_mm = 0.2 (0.01..2)            the burned spot's diameter (the preview draws each run
//                                      with it: dots and lines finer than the spot overlap)
//   width_mm = 100 (1..5000)           the engraving's width; its height keeps the aspect
//   position_mm = [10, 10]             bed mm of its front-left corner (X from the bed's left
//                                      edge, Y from its front edge), each 0..5000
//   speed_mm_min = 3000 (1..100000)    scanning feed
//   min_power_pct = 0, max_power_pct = 100 (0..100, min <= max)   % of s_max; min is the
//                                      power of the lightest burned grey (greyscale only)
//   gamma = 1.0 (0.1..10)              darkness^gamma: above 1 lightens the mid-tones
//   negative = false                   burn the light parts instead of the dark ones
//   threshold = 0.5 (0..1)             darkness that `threshold` dithering burns
//   bidirectional = true               scan lines alternate direction
//   overscan_mm = 0 (0..100)           run-up before the first and after the last dot of a
//                                      line; 0 = from speed_mm_min and [laser]
//                                      acceleration_mm_s2 (raster.h overscan_for)
//   laser = the [laser] table (laser_params.h: work area, s_max, motion; its layers unused)
//
// Thread-safe (no shared state). Errors are ParamError "FILE:LINE: key 'k': ...".
#pragma once

#include <optional>
#include <string>
#include <toml++/toml.h>

#include "algorithms/laser/raster.h"
#include "convert/common/laser_params.h"

namespace atelier {

struct EngraveParams {
  laser::Dither dither = laser::Dither::jarvis;
  double dpi = 127;
  double line_interval_mm = 0.2;
  double spot_mm = 0.2;
  double width_mm = 100;
  double position_x_mm = 10, position_y_mm = 10;
  double speed_mm_min = 3000;
  double min_power_pct = 0, max_power_pct = 100;
  double gamma = 1;
  bool negative = false;
  double threshold = 0.5;
  bool bidirectional = true;
  double overscan_mm = 0;  // 0 = from speed and acceleration
  LaserParams laser;
};

// Throws ParamError naming file, line and key.
EngraveParams read_engrave_params(const toml::table& params, const std::string& source);

}  // namespace atelier
