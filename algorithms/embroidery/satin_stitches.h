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

// Sews one column along `curve` (sampled finely, e.g. every spacing_px / 8, see fit_bspline):
// at each sample inside the mask the perpendicular's two exits from the mask are the cut's
// edges; cuts are taken so that consecutive ones advance at most about spacing_px / 2 on the
// centre and on both edges, and the needle alternates between their edges (pull compensation
// added). Samples off the mask are skipped. Columns wider than max_span (with pull
// compensation) are split in parallel sub-columns; a stitch still longer than max_span is
// split in equal stitches; a stitch that would cross bare fabric (beyond the mask grown by
// the pull compensation) is replaced by travel inside. Returns false when no sample lies
// inside the mask (nothing sewn). Bounded: one pass over the samples per sub-column.
bool satin_column(const cv::Mat1b& mask, const SampledCurve& curve, const ColumnParams& p, StitchSink& sink);

// The share of a region its own stitches must cover (issue 21: thread 0.4 mm wide, see
// coverage.h), below which satin and edge regions top up with fill or are filled instead.
inline constexpr double kCoverTarget = 0.98;

// The share of `mask` the thread of `sink` (mask pixels) covers, [0, 1] (coverage.h).
double sink_coverage(const cv::Mat1b& mask, const StitchSink& sink, double px_per_mm);

// Tops up `sink` (stitches in mask pixels) until its thread covers `mask`: each part its
// stitches leave bare that is larger than a 0.5 mm square is filled (fill_into at `angle`,
// grown by a pixel to meet the thread around it). Returns the coverage reached, [0, 1].
// Bounded: one fill per bare part, one measurement before and after.
double cover_bare(const cv::Mat1b& mask, double angle, const StitchParams& params, StitchSink& sink);

// The sink's stitches in mm (offset_px as in fill_region), each needle point farther than
// limit_px from every mask pixel centre moved onto the nearest one: travel that found no path
// inside the region (a neck narrower than its cells) runs straight and may leave it.
std::vector<StitchPoint> on_region_mm(const cv::Mat1b& mask, const StitchSink& sink, cv::Point2f offset_px,
                                      double px_per_mm, double limit_px);

// A satin region: its skeleton branches (shorter than 1.5 mm dropped) as columns, nearest
// first with travel inside the region; the parts the columns leave bare (blobby or concave
// parts perpendicular cuts miss) are filled (cover_bare), and a region still below
// kCoverTarget, or with no usable branch, is filled whole (tatami at fallback_angle,
// radians) instead. No satin stitch is longer than satin_max_mm (wider columns are split in
// parallel sub-columns, longer single spans in equal stitches); no stitch crosses bare
// fabric beyond the pull compensation. Returns mm (offset_px as in fill_region).
std::vector<StitchPoint> satin_region(const cv::Mat1b& mask, cv::Point2f offset_px, double fallback_angle,
                                      const StitchParams& params);

}  // namespace atelier::embroidery
