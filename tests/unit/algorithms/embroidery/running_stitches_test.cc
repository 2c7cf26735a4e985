// Edge stitches (edge_region, algorithms/embroidery/running_stitches.h): a running stitch along
// a thin line, a narrow satin on a wide edge.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>

#include "algorithms/embroidery/running_stitches.h"
#include "tests/unit/algorithms/embroidery/stitches_fixture.h"

namespace atelier::embroidery {
namespace {

using test::params8;
using test::stitch_lengths;
using test::to_px;
using test::worst_outside;

TEST(EmbroideryStitches, EdgeRunningStitchFollowsAThinLine) {
  cv::Mat1b m(200, 300, uchar(0));
  cv::line(m, {20, 180}, {280, 20}, 255, 3);  // 0.4 mm: thinner than edge_satin_min_mm
  const StitchParams p = params8();
  const auto pts = edge_region(m, {0, 0}, 0.0, p);
  const auto lengths = stitch_lengths(pts);
  ASSERT_GT(lengths.size(), 20u);  // 38 mm at 1.5 mm
  for (double l : lengths) EXPECT_LE(l, p.running_stitch_mm + 1e-6);
  EXPECT_LE(worst_outside(m, pts), 1.0);
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

}  // namespace
}  // namespace atelier::embroidery
