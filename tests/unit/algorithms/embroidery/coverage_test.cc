// Thread coverage (algorithms/embroidery/coverage.h): the capsule raster is exact against a
// brute-force distance, jumps lay no thread, and the per-style summary counts what it says.
#include "algorithms/embroidery/coverage.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace atelier::embroidery {
namespace {

double distance_to_segment(cv::Point2d p, cv::Point2d a, cv::Point2d b) {
  const cv::Point2d d = b - a;
  const double l2 = d.dot(d);
  const double t = l2 > 0 ? std::clamp((p - a).dot(d) / l2, 0.0, 1.0) : 0.0;
  return cv::norm(p - (a + d * t));
}

TEST(EmbroideryCoverage, ThreadRasterIsTheExactCapsule) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> pos(-5, 45), rad(0.3f, 4.0f);
  int mismatches = 0, marked = 0;
  for (int k = 0; k < 300; ++k) {
    const cv::Point2f a(pos(rng), pos(rng));
    const cv::Point2f b = k % 10 == 0 ? a : cv::Point2f(pos(rng), pos(rng));  // some zero-length
    const double r = rad(rng);
    cv::Mat1b canvas(40, 40, uchar(0));
    draw_thread(canvas, a, b, r);
    for (int y = 0; y < 40; ++y)
      for (int x = 0; x < 40; ++x) {
        const double d = distance_to_segment({double(x), double(y)}, a, b);
        if (std::abs(d - r) < 1e-4) continue;  // on the boundary: either way
        mismatches += (d < r) != (canvas(y, x) != 0);
        marked += canvas(y, x) != 0;
      }
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(marked, 10000);
}

TEST(EmbroideryCoverage, ARunningStitchCoversAThreadWidthAndAJumpLaysNoThread) {
  const double ppm = 10;
  cv::Mat1b stripe(40, 220, uchar(0));
  stripe(cv::Rect(10, 10, 200, 20)).setTo(255);  // 20 mm x 2 mm
  // One line of stitches along the middle: pixels within 0.2 mm = 2 px, 5 rows of 20.
  std::vector<StitchPoint> run;
  for (int x = 10; x <= 209; x += 15) run.push_back({x / ppm, 19.5 / ppm, StitchKind::stitch});
  run.push_back({20.9, 1.95, StitchKind::stitch});
  EXPECT_NEAR(region_coverage(stripe, run, {0, 0}, ppm), 4.0 / 20.0, 0.01);
  // The same points with a jump in the middle: the half after the jump's gap is bare.
  std::vector<StitchPoint> with_jump = {{1.0, 1.95, StitchKind::stitch}, {10.0, 1.95, StitchKind::stitch},
                                        {20.9, 1.95, StitchKind::jump}, {20.9, 1.95, StitchKind::stitch}};
  EXPECT_NEAR(region_coverage(stripe, with_jump, {0, 0}, ppm), 4.0 / 20.0 * 91 / 200, 0.01);
  // A zig-zag across it 0.4 mm apart covers it all; the offset maps mm onto the mask.
  std::vector<StitchPoint> zig;
  for (int i = -4; i <= 104; ++i)
    zig.push_back({(100 + 10 + i * 2) / ppm, ((i + 4) % 2 ? 100 + 30 : 100 + 9) / ppm, StitchKind::stitch});
  EXPECT_GT(region_coverage(stripe, zig, {100, 100}, ppm), 0.999);
  EXPECT_DOUBLE_EQ(region_coverage(cv::Mat1b(5, 5, uchar(0)), zig, {0, 0}, ppm), 1.0);
}

TEST(EmbroideryCoverage, PerStyleSummaryCountsRegionsOverTheArea) {
  const std::vector<RegionCoverage> r = {
      {0, Style::satin, 10.0, 0.90}, {1, Style::satin, 3.0, 0.10},  // too small: left out
      {2, Style::satin, 50.0, 1.00}, {3, Style::edge, 5.0, 0.985},
  };
  const auto s = coverage_by_style(r);
  EXPECT_EQ(s[int(Style::satin)].regions, 2);
  EXPECT_DOUBLE_EQ(s[int(Style::satin)].min, 0.90);
  EXPECT_DOUBLE_EQ(s[int(Style::satin)].mean, 0.95);
  EXPECT_EQ(s[int(Style::satin)].below, 1);
  EXPECT_EQ(s[int(Style::edge)].below, 0);
  EXPECT_EQ(s[int(Style::long_short)].regions, 0);
  EXPECT_DOUBLE_EQ(s[int(Style::long_short)].min, 1.0);
}

}  // namespace
}  // namespace atelier::embroidery
