// Satin stitches (algorithms/embroidery/satin_stitches.h): across the column, wide columns
// split, spans bounded where the width jumps.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>

#include "algorithms/embroidery/satin_stitches.h"
#include "tests/unit/algorithms/embroidery/stitches_fixture.h"

namespace atelier::embroidery {
namespace {

using test::coverage;
using test::kPpm;
using test::params8;
using test::rasterise;
using test::stitch_lengths;
using test::to_px;
using test::worst_outside;

TEST(EmbroideryStitches, SatinStitchesGoAcrossTheColumn) {
  cv::Mat1b m(260, 400, uchar(0));
  const cv::Point2f c(200, 230);
  cv::ellipse(m, cv::Point(200, 230), {150, 150}, 0, 200, 340, 255, 30);  // a 3.75 mm wide arc
  const StitchParams p = params8();
  const auto pts = satin_region(m, {0, 0}, 0.0, p);
  const auto px = to_px(pts);
  int spans = 0;
  for (size_t i = 1; i < px.size(); ++i) {
    const cv::Point2f d = px[i] - px[i - 1];
    const double len = cv::norm(d);
    if (len < 20) continue;  // underlay and travel run along; spans are ~30 px
    ++spans;
    const cv::Point2f mid = (px[i] + px[i - 1]) * 0.5f, r = mid - c;
    const cv::Point2f along(-r.y, r.x);  // the stripe's direction at the span
    const double cos_a = std::abs(d.dot(along)) / (len * cv::norm(along));
    EXPECT_LT(cos_a, std::cos(60.0 * CV_PI / 180)) << "span " << i;
  }
  EXPECT_GT(spans, 150);  // ~230 zig-zags along 366 px at 1.6 px
  // Needle points stay on the stroke, pull compensation allowed.
  EXPECT_LE(worst_outside(m, pts), 1.0 + p.satin_pull_comp_mm * kPpm);
  // And cover it (threads about 0.4 mm = 3 px wide).
  EXPECT_GE(coverage(m, rasterise(pts, m.size(), 3)), 0.95);
}

TEST(EmbroideryStitches, WideSatinColumnIsSplit) {
  cv::Mat1b m(200, 480, uchar(0));
  cv::line(m, {60, 100}, {420, 100}, 255, 120);  // a 15 mm wide stroke with round ends
  const StitchParams p = params8();
  const auto pts = satin_region(m, {0, 0}, 0.0, p);
  double longest = 0;
  for (double l : stitch_lengths(pts)) longest = std::max(longest, l);
  EXPECT_GT(longest, 6.0);  // sewn as satin (not a fill fallback) ...
  EXPECT_LE(longest, std::hypot(p.satin_max_mm + 2 * p.satin_pull_comp_mm, p.satin_spacing_mm));  // ... split
  EXPECT_GE(coverage(m, rasterise(pts, m.size(), 3)), 0.95);  // threads about 0.4 mm = 3 px wide
}

TEST(EmbroideryStitches, SatinSpansStayBoundedWhereTheWidthJumps) {
  // A 4 mm stripe with a 12 mm block on one side and a tight hairpin: neighbouring cuts differ
  // by far more than a sub-column's width there.
  cv::Mat1b m(300, 480, uchar(0));
  cv::line(m, {40, 80}, {440, 80}, 255, 32);
  cv::rectangle(m, cv::Rect(200, 80, 96, 96), 255, cv::FILLED);
  cv::ellipse(m, cv::Point(240, 230), {60, 30}, 0, 180, 360, 255, 24);
  const StitchParams p = params8();
  const auto pts = satin_region(m, {0, 0}, 0.0, p);
  ASSERT_FALSE(pts.empty());
  for (double l : stitch_lengths(pts))
    ASSERT_LE(l, std::hypot(p.satin_max_mm + 2 * p.satin_pull_comp_mm, p.satin_spacing_mm) + 1e-6);
}

}  // namespace
}  // namespace atelier::embroidery
