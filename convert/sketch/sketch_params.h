// Parameters of `sketch` jobs (an image redrawn as human-like pencil lines), read strictly from
// the merged parameter table (config [sketch] < sidecar < --set).
//
// Keys (default, range):
//   pencil = "HB"         a shipped grade (2H, H, F, HB, B, 3B, 6B, 8B) or a profile file
//                         NAME.toml (from `atelier-convert pencil-profile`), relative to the file
//                         that names it
//   squiggle = 5 (0..50)  D of the paper, in drawing px: how far a line may wander
//   seed = 1 (0..2^53)    every line is different, the same seed gives the same drawing
//   scale = 2 (0.25..8)   drawing px per image px (the preview is this much larger than the input;
//                         longer side capped at 4096 px, see report `scale`)
//   min_stroke_px = 6 (0..1000)  image px: shorter strokes are dropped
//   smoothing_px = 9 (0..31)     edge-preserving (bilateral) smoothing diameter before Canny; 0 = none
//   canny_low = 0, canny_high = 0 (0..1000)  Canny thresholds; 0 = from the image
//   simplify_px = 1.5 (0.1..50)  image px: contour simplification
//   max_lines = 20000 (1..1000000)  the longest strokes are kept (plus all hatching up to it)
//   hatching = false      fill dark regions with hatch lines drawn the same way (paper fig. 7)
//   hatch_level = 0.35 (0..1)    darker than this (0 black .. 1 white) is hatched ...
//   cross_level = 0.15 (0..1)    ... and darker than this cross-hatched
//   hatch_spacing_px = 6 (1..200), hatch_angle_deg = 45 (-360..360)   image px, degrees
//   width_mm = 100 (1..5000)     the engraving's width (height follows the image)
//   position_mm = [10, 10]       its top-left corner, mm from the bed's rear-left corner
//   speed_mm_min = 3000 (1..100000)  engraving feed
//   power_pct = 0 (0..100)       0 = by pencil grade: the pencil's darkness (1 - mean grey / 255)
//   laser = the [laser] table (laser_params.h: work area, s_max, origin; its layers are not used)
//
// Thread-safe (no shared state). Errors are ParamError "FILE:LINE: key 'k': ...".
#pragma once

#include <filesystem>

#include <cstdint>
#include <string>
#include <toml++/toml.h>

#include "convert/common/laser_params.h"

namespace atelier {

struct SketchParams {
  std::string pencil = "HB";   // grade name, or an absolute path to a profile .toml
  double squiggle = 5;
  std::uint64_t seed = 1;
  double scale = 2;
  double min_stroke_px = 6;
  int smoothing_px = 9;
  double canny_low = 0, canny_high = 0;
  double simplify_px = 1.5;
  int max_lines = 20000;
  bool hatching = false;
  double hatch_level = 0.35, cross_level = 0.15;
  double hatch_spacing_px = 6, hatch_angle_deg = 45;
  double width_mm = 100;
  double position_x_mm = 10, position_y_mm = 10;
  double speed_mm_min = 3000;
  double power_pct = 0;
  LaserParams laser;
};

// Throws ParamError naming file, line and key (an unknown grade lists the shipped ones).
SketchParams read_sketch_params(const toml::table& params, const std::string& source);


// The [sketch] section's `pencil` when it is a profile file (.toml), not a grade.
void resolve_sketch_config_paths(toml::table& section, const std::filesystem::path& config_dir,
                               const std::filesystem::path& state_dir);

}  // namespace atelier
