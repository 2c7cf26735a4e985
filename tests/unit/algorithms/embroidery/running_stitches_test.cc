// Edge stitches (edge_region, algorithms/embroidery/running_stitches.h): a running stitch along
// a thin line, a narrow satin on a wide edge.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>

#include "algorithms/embroidery/coverage.h"
#include "algorithms/embroidery/running_stitches.h"
#include "algorithms/embroidery/satin_stitches.h"
#include "tests/unit/algorithms/embroidery/stitches_fixture.h"

namespace atelier::embroidery {
namespace {

using test::params8;
using test::stitch_lengths;
using test::to_px;
using test::worst_outside;

TEST(EmbroideryStitches, EdgeRunningStitchFollowsAThinLine) {
  cv::Mat1b m(200, 300, uchar(0));
  cv::line(m, {20, 180}, {280, 20}, 255, 2);  // 0.25 mm: thinner than the thread
  const StitchParams p = params8();
  const auto pts = edge_region(m, {0, 0}, 0.0, p);
  const auto lengths = stitch_lengths(pts);
  ASSERT_GT(lengths.size(), 20u);  // 38 mm at 1.5 mm
  for (double l : lengths) EXPECT_LE(l, p.running_stitch_mm + 1e-6);
  EXPECT_LE(worst_outside(m, pts), 1.0);
  EXPECT_GE(region_coverage(m, pts, {0, 0}, test::kPpm), kCoverTarget);  // the thread is wider than the line
  // From one end of the line to the other.
  const auto px = to_px(pts);
  cv::Point2f lo = px[0], hi = px[0];
  for (const auto& q : px) lo.x = std::min(lo.x, q.x), hi.x = std::max(hi.x, q.x);
  EXPECT_LT(lo.x, 26);
  EXPECT_GT(hi.x, 274);
}

TEST(EmbroideryStitches, WideEdgeGetsANarrowSatin) {
  cv::Mat1b m(200, 300, uchar(0));
  cv::line(m, {20, 100}, {280, 100}, 255, 12);  // 1.5 mm >= edge_satin_min_mm
  const StitchParams p = params8();
  const auto px = to_px(edge_region(m, {0, 0}, 0.0, p));
  int across = 0;
  for (size_t i = 1; i < px.size(); ++i) {
    const cv::Point2f d = px[i] - px[i - 1];
    if (std::abs(d.y) > 8 && std::abs(d.y) > 3 * std::abs(d.x)) ++across;
  }
  EXPECT_GT(across, 140);  // 260 px at 1.6 px per zig-zag: about 160 spans
}

TEST(EmbroideryStitches, EdgeStrokesWiderThanTheThreadAreCovered) {
  // Issue 21: a running stitch lays 0.4 mm of thread; strokes of 0.6 to 1.5 mm, straight and
  // curved, must still be covered (narrow satin, or fill).
  const StitchParams p = params8();
  for (int width_px : {5, 7, 9, 12}) {
    cv::Mat1b m(260, 400, uchar(0));
    cv::ellipse(m, cv::Point(200, 230), {160, 160}, 0, 200, 340, 255, width_px);
    cv::line(m, {30, 240}, {370, 240}, 255, width_px);
    const auto pts = edge_region(m, {0, 0}, 0.0, p);
    EXPECT_GE(region_coverage(m, pts, {0, 0}, test::kPpm), kCoverTarget) << width_px << " px";
    EXPECT_LE(worst_outside(m, pts), 1.0 + p.satin_pull_comp_mm * test::kPpm) << width_px << " px";
  }
}

}  // namespace
}  // namespace atelier::embroidery
