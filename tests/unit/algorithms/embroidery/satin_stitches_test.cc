// Satin stitches (algorithms/embroidery/satin_stitches.h): across the column, wide columns
// split, spans bounded where the width jumps.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>

#include "algorithms/embroidery/coverage.h"
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

// Issue 21 points 2 and 9 on shapes where perpendicular cuts from the skeleton fail.
// Distance (px) from p to the region: the union of its pixels' squares.
double outside_by(const cv::Mat1b& m, cv::Point2f p) {
  double best = 1e9;
  for (int y = cvFloor(p.y) - 12; y <= cvCeil(p.y) + 12; ++y)
    for (int x = cvFloor(p.x) - 12; x <= cvCeil(p.x) + 12; ++x)
      if (x >= 0 && y >= 0 && x < m.cols && y < m.rows && m(y, x))
        best = std::min(best, std::hypot(std::max(0.0, std::abs(p.x - x) - 0.5), std::max(0.0, std::abs(p.y - y) - 0.5)));
  return best;
}

struct SatinCheck {
  double coverage, worst_needle_px, worst_thread_px, longest_mm;
};

// Sews `m` as a satin region and measures what a user would see: the share of it covered by
// thread, how far needle points and the thread between them leave it, the longest stitch.
SatinCheck sew_satin(const cv::Mat1b& m) {
  const StitchParams p = params8();
  const auto pts = satin_region(m, {0, 0}, 0.3, p);
  SatinCheck c{region_coverage(m, pts, {0, 0}, kPpm), 0, 0, 0};
  for (double l : stitch_lengths(pts)) c.longest_mm = std::max(c.longest_mm, l);
  const auto px = to_px(pts);
  for (const cv::Point2f& q : px) c.worst_needle_px = std::max(c.worst_needle_px, outside_by(m, q));
  for (size_t i = 1; i < pts.size(); ++i) {
    if (pts[i].kind != StitchKind::stitch || pts[i - 1].kind != StitchKind::stitch) continue;
    const cv::Point2f a(pts[i - 1].x_mm * kPpm, pts[i - 1].y_mm * kPpm), b(pts[i].x_mm * kPpm, pts[i].y_mm * kPpm);
    const int steps = std::max(1, static_cast<int>(cv::norm(b - a) / 0.5));
    for (int k = 0; k <= steps; ++k)
      c.worst_thread_px = std::max(c.worst_thread_px, outside_by(m, a + (b - a) * (static_cast<float>(k) / steps)));
  }
  return c;
}

void expect_sewn_well(const cv::Mat1b& m, const char* what) {
  const StitchParams p = params8();
  const SatinCheck c = sew_satin(m);
  const double allowed = p.satin_pull_comp_mm * kPpm + 0.5;  // pull compensation + half a pixel
  EXPECT_GE(c.coverage, kCoverTarget) << what;
  EXPECT_LE(c.worst_needle_px, allowed) << what;
  EXPECT_LE(c.worst_thread_px, allowed) << what << ": a stitch crosses bare fabric";
  EXPECT_LE(c.longest_mm, p.satin_max_mm + 1e-6) << what;
}

TEST(EmbroideryStitches, SatinCoversACrescent) {
  cv::Mat1b m(400, 400, uchar(0));
  cv::circle(m, {200, 200}, 140, 255, cv::FILLED);
  cv::circle(m, {235, 200}, 125, 0, cv::FILLED);  // 6 mm wide at its back, thin horns
  expect_sewn_well(m, "crescent");
}

TEST(EmbroideryStitches, SatinCoversABlobWithConcaveBays) {
  cv::Mat1b m(300, 300, uchar(0));
  cv::circle(m, {150, 150}, 80, 255, cv::FILLED);
  for (int k = 0; k < 5; ++k) {
    const double a = k * 2 * CV_PI / 5;
    cv::circle(m, {150 + cvRound(88 * std::cos(a)), 150 + cvRound(88 * std::sin(a))}, 30, 0, cv::FILLED);
  }
  expect_sewn_well(m, "blob with bays");
}

TEST(EmbroideryStitches, SatinCoversAColumnEndingInABlob) {
  cv::Mat1b m(300, 480, uchar(0));
  cv::line(m, {40, 150}, {280, 150}, 255, 32);  // a 4 mm column ...
  cv::circle(m, {350, 150}, 80, 255, cv::FILLED);  // ... into a 20 mm blob
  expect_sewn_well(m, "column and blob");
}

TEST(EmbroideryStitches, SatinTriangleHasNoSpikesAtItsCorners) {
  cv::Mat1b m(300, 420, uchar(0));
  const std::vector<cv::Point> tri = {{30, 40}, {390, 110}, {50, 260}};
  cv::fillConvexPoly(m, tri, 255);
  expect_sewn_well(m, "triangle");
  cv::Mat1b thin(200, 420, uchar(0));
  const std::vector<cv::Point> sliver = {{20, 100}, {400, 80}, {30, 140}};  // sharp corners
  cv::fillConvexPoly(thin, sliver, 255);
  expect_sewn_well(thin, "thin triangle");
}

TEST(EmbroideryStitches, NoSatinStitchIsLongerThanTheMaximum) {
  // A 12 mm wide stroke: with pull compensation one span would be 12.4 mm.
  cv::Mat1b m(200, 480, uchar(0));
  cv::line(m, {60, 100}, {420, 100}, 255, 96);
  for (double max_mm : {8.0, 5.0}) {
    StitchParams p = params8();
    p.satin_max_mm = max_mm;
    const auto pts = satin_region(m, {0, 0}, 0.0, p);
    double longest = 0;
    for (double l : stitch_lengths(pts)) longest = std::max(longest, l);
    EXPECT_LE(longest, max_mm + 1e-6);
    EXPECT_GT(longest, 0.6 * max_mm);  // still satin, split in columns
    EXPECT_GE(region_coverage(m, pts, {0, 0}, kPpm), kCoverTarget);
  }
}

}  // namespace
}  // namespace atelier::embroidery
