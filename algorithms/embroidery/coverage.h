// Thread coverage (issue 21, point 2): how much of a region its own stitches cover.
//
// The measure: a region's pixel is covered when its centre lies within `radius` (0.2 mm: a
// thread 0.4 mm wide) of a segment of thread, a segment being two consecutive needle
// penetrations (StitchKind::stitch) of the region's own run; a jump or a trim between them
// lays no thread. Coverage = covered region pixels / region pixels.
//
// Units: masks in pixels (a pixel's centre is its integer coordinate, x right, y down);
// stitch points in mm, mapped to the mask's pixels as px = mm * px_per_mm - offset_px (the
// inverse of StitchSink::to_mm, so a region generator's output with its own offset maps back
// onto its mask). Pure functions on value types; thread-safe. Cost: O(rows crossed + pixels
// marked) per segment, no search over stitches.
#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <vector>

#include "algorithms/embroidery/design.h"
#include "algorithms/embroidery/stitch_plan.h"
#include "algorithms/embroidery/stitch_planner.h"

namespace atelier::embroidery {

inline constexpr double kThreadRadiusMm = 0.2;  // half of a 0.4 mm thread

// Sets to 255 every pixel of `canvas` whose centre lies within radius_px of the segment a-b
// (exact capsule, row by row). Pixels outside the canvas are ignored.
void draw_thread(cv::Mat1b& canvas, cv::Point2f a, cv::Point2f b, double radius_px);

// The pixels of a `size` canvas covered by the thread of `pts` (see above).
cv::Mat1b thread_pixels(cv::Size size, const std::vector<StitchPoint>& pts, cv::Point2f offset_px, double px_per_mm,
                        double radius_mm = kThreadRadiusMm);

// Covered share of the mask's set pixels, in [0, 1]; 1 for an empty mask.
double region_coverage(const cv::Mat1b& mask, const std::vector<StitchPoint>& pts, cv::Point2f offset_px,
                       double px_per_mm, double radius_mm = kThreadRadiusMm);

// One region's stitches as the planner makes them (fill_region, satin_region or edge_region
// by style), in mm with offset 0: px = mm * px_per_mm lands on the region's own mask (bbox
// frame). Empty for an empty mask.
std::vector<StitchPoint> region_stitches(const Region& region, double direction, const StitchParams& params);

struct RegionCoverage {
  int region = 0;
  Style style = Style::long_short;
  double area_mm2 = 0;
  double coverage = 1;  // [0, 1]
};

// Coverage of every region of `seg` by `stitches` (one vector per region, offsets as given
// per region: offset_px[i], or 0 when offset_px is empty). Regions run in parallel.
std::vector<RegionCoverage> regions_coverage(const Segmentation& seg,
                                             const std::vector<std::vector<StitchPoint>>& stitches,
                                             const std::vector<cv::Point2f>& offset_px, double px_per_mm);

// Convenience: region_stitches() for every region (in parallel), then regions_coverage().
std::vector<RegionCoverage> design_coverage(const Segmentation& seg, const std::vector<double>& directions,
                                            const StitchParams& params);

// Per style, over regions larger than min_area_mm2: the least and mean coverage and how many
// fall below `threshold`. A style with no such region has regions = 0, min = mean = 1.
struct StyleCoverage {
  int regions = 0;
  double min = 1, mean = 1;
  int below = 0;
};
std::array<StyleCoverage, kStyleCount> coverage_by_style(const std::vector<RegionCoverage>& regions,
                                                         double min_area_mm2 = 4.0, double threshold = 0.98);

}  // namespace atelier::embroidery
