// The preview of a parquetry plan rendered from the scans themselves: every piece is the wood
// under its source outline, moved by its rigid motion into the result and clipped to its
// target outline, with thin dark joints between the pieces (as the glued work will look).
//
// Units: the plan's result mm; the image has `px_per_mm` pixels per mm, origin at the
// result's top-left. Pure (no I/O, clocks or logging); thread-safe.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "algorithms/parquetry/plan.h"
#include "algorithms/parquetry/sheet.h"

namespace atelier::parquetry {

struct RenderOptions {
  double px_per_mm = 4;       // wanted resolution
  int max_px = 4000;          // cap on the longer side (lowers px_per_mm for large results)
  double joint_mm = 0.3;      // width of the dark line drawn along every piece's outline
  cv::Scalar joint_bgr{40, 40, 40};
};

// The resolution render_plan uses for `plan` under `options` (px per mm).
double render_px_per_mm(const Plan& plan, const RenderOptions& options);

// CV_8UC3 BGR, round(width_mm * s) x round(height_mm * s) with s = render_px_per_mm. Pixels
// no piece covers stay black. Throws std::invalid_argument when a piece names a sheet not in
// `sheets`.
cv::Mat render_plan(const Plan& plan, const std::vector<Sheet>& sheets,
                    const RenderOptions& options = {});

}  // namespace atelier::parquetry
