// One hand-drawn pencil line between two end points (`atelier-convert line - OUT --set
// from=X,Y --set to=X,Y --set pencil=6B`): the paper's path (algorithms/pencil/path.h) and
// texture (texture.h) at the given coordinates.
//
// Parameters (strict; unknown keys are errors):
//   from, to   end points in px, "X,Y" strings or [X, Y] arrays; required; finite, |X|,|Y| <= 20000
//   pencil     a shipped grade (2H .. 8B) or a .toml profile path (see pencil_profile_file.h); "HB"
//   squiggle   D in px, the largest displacement of a control point (paper: 5); 0..100; 5
//   seed       the path's and the texture's seed; 0..2^63-1; 1
//   margin     paper around the line's bounding box, px; 0..1000; 20
// Writes into `out` (created if missing), each file atomically:
//   line.png     8-bit grey, paper white (255): the line's bounding box (the path's points plus
//                its half width) grown by `margin`; canvas pixel (0, 0) is at `origin` in line
//                coordinates, so a path point p is drawn at p - origin
//   line.json    {"from", "to", "pencil", "squiggle", "seed", "origin": [x, y], "control":
//                [[x, y] ...], "path": [[x, y] ...]} (line coordinates, 3 decimals)
//   report.json  the parameters, length_px (along the path), points, canvas size, milliseconds
// Not thread-safe per call; separate calls may run concurrently.
#pragma once

#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <toml++/toml.h>

#include "convert/convert.h"

namespace atelier {

inline constexpr double kLineMaxCoordinate = 20000.0;  // |x|, |y| of an end point, px

struct LineParams {
  cv::Point2d from, to;
  std::string pencil = "HB";
  double squiggle = 5.0;
  std::uint64_t seed = 1;
  int margin_px = 20;
};

// Throws ParamError "SOURCE:LINE: key 'from': ..." for a missing, malformed or out-of-range value
// or an unknown key.
LineParams read_line_params(const toml::table& params, const std::string& source);

// Draws the line and writes line.png, line.json and report.json into `out`. Relative pencil
// paths are relative to the file the `pencil` value came from (the cwd for --set). Throws
// ParamError (parameters), ConvertError (an unknown pencil or bad profile file, a canvas of more
// than limits.max_pixels, output files).
ConvertResult convert_line(const toml::table& params, const std::string& source, const std::filesystem::path& out,
                           const ImageLimits& limits = {});

}  // namespace atelier
