// Satin columns along a region's skeleton branches (paper 5.2 skeleton, B-spline), sewn as a
// zig-zag across the column with pull compensation and a centre-walk underlay.
// Units: mask pixels in, millimetres out (see StitchSink::to_mm). Pure; thread-safe.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "algorithms/embroidery/running_stitches.h"
#include "algorithms/embroidery/skeleton.h"
#include "algorithms/embroidery/stitch_plan.h"
#include "algorithms/embroidery/stitch_planner.h"

namespace atelier::embroidery {

struct ColumnParams {
  double spacing_px;   // zig-zag peak to peak along the column (same side)
  double pull_px;      // each side widened by this
  double max_span_px;  // wider columns split into equal parallel sub-columns; <= 0: never split
  bool underlay;       // centre walk first (running stitches of run_px)
  double run_px;
};

// Sews one column along `curve` (sampled every spacing_px / 2, see fit_bspline): at each
// sample inside the mask the perpendicular's two exits from the mask are the column's edges;
// the needle alternates between them. Samples off the mask are skipped. A span longer than
// hypot(max_span + 2 pull, spacing) (the width jumping between neighbouring cuts) is run in
// stitches of the sink's length instead. Returns false when no sample lies inside the mask
// (nothing sewn).
bool satin_column(const cv::Mat1b& mask, const SampledCurve& curve, const ColumnParams& p, StitchSink& sink);

// A satin region: its skeleton branches (shorter than 1.5 mm dropped) as columns, nearest
// first with travel inside the region; a region with no usable branch is filled (tatami at
// fallback_angle, radians). Returns mm (offset_px as in fill_region).
std::vector<StitchPoint> satin_region(const cv::Mat1b& mask, cv::Point2f offset_px, double fallback_angle,
                                      const StitchParams& params);

}  // namespace atelier::embroidery
