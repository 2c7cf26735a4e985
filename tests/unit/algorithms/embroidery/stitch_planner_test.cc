// The stitch planner (algorithms/embroidery/stitch_planner.h): colour blocks, trims, tie-offs,
// end code, stitch lengths, coverage of every region and the hoop check.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "algorithms/embroidery/stitch_planner.h"
#include "tests/unit/algorithms/embroidery/stitches_fixture.h"

namespace atelier::embroidery {
namespace {

using test::coverage;
using test::expect_long_jumps_trimmed;
using test::kPpm;
using test::params8;
using test::stitch_lengths;

// ---- planner ----------------------------------------------------------------------------
Region region_from(const cv::Mat1b& full, int color, Style style) {
  Region r;
  r.color = color;
  r.style = style;
  r.bbox = cv::boundingRect(full);
  r.mask = full(r.bbox).clone();
  r.area_px = cv::countNonZero(r.mask);
  return r;
}

Segmentation drawn_design() {
  Segmentation seg;
  seg.size = {480, 400};
  seg.palette.bgr = {{200, 40, 40}, {40, 200, 40}, {40, 40, 200}};
  auto canvas = [&] { return cv::Mat1b(seg.size, uchar(0)); };
  cv::Mat1b a = canvas(), b = canvas(), c = canvas(), d = canvas(), e = canvas();
  cv::circle(a, {110, 120}, 80, 255, cv::FILLED);                        // colour 0, fill
  cv::rectangle(b, cv::Rect(300, 250, 140, 110), 255, cv::FILLED);       // colour 0, fill, far away
  cv::ellipse(c, cv::Point(240, 330), {150, 150}, 0, 200, 340, 255, 24);  // colour 1, satin arc
  cv::line(d, {20, 380}, {460, 380}, 255, 3);                            // colour 2, edge
  cv::line(e, {300, 40}, {440, 200}, 255, 3);                            // colour 2, edge, apart
  seg.regions = {region_from(c, 1, Style::satin), region_from(d, 2, Style::edge), region_from(a, 0, Style::long_short),
                 region_from(b, 0, Style::long_short), region_from(e, 2, Style::edge)};
  for (size_t i = 0; i < seg.regions.size(); ++i) seg.regions[i].id = static_cast<int>(i);
  return seg;
}

TEST(EmbroideryStitches, PlanHasColourBlocksTrimsAndAnEnd) {
  const Segmentation seg = drawn_design();
  const StitchParams p = params8();
  const StitchPlan plan = plan_stitches(seg, std::vector<double>(seg.regions.size(), 0.5), p);
  ASSERT_FALSE(plan.points.empty());
  EXPECT_EQ(plan.points.back().kind, StitchKind::end);
  EXPECT_NO_THROW(validate_plan(plan));
  const StitchStats st = stitch_stats(plan);
  EXPECT_EQ(st.color_changes, 2);  // three colours
  // Colour blocks in palette order of first use, the long-short background first.
  ASSERT_EQ(plan.colors_rgb.size(), 3u);
  EXPECT_EQ(plan.colors_rgb[0], 0x2828C8u);  // palette 0 (B,G,R = 200,40,40)
  EXPECT_EQ(plan.colors_rgb[1], 0x28C828u);
  EXPECT_EQ(plan.colors_rgb[2], 0xC82828u);
  // Two far-apart regions in one colour: at least one trim besides the colour changes.
  EXPECT_GT(st.trims, st.color_changes);
  expect_long_jumps_trimmed(plan.points, p.trim_jump_mm);
  // Stitch lengths: fill and running stitches within fill_max_stitch_mm, satin spans within
  // satin_max_mm + 2 pull compensation, and nothing a DST file cannot hold.
  const double satin_bound = std::hypot(p.satin_max_mm + 2 * p.satin_pull_comp_mm, p.satin_spacing_mm);
  for (double l : stitch_lengths(plan.points)) {
    EXPECT_LE(l, std::max(p.fill_max_stitch_mm, satin_bound) + 1e-6);
    EXPECT_LE(l, 12.1);
  }
  // The design is centred: the image's centre is the origin.
  EXPECT_NEAR((st.min_x_mm + st.max_x_mm) / 2, 0.0, 3.0);
  EXPECT_LT(st.max_x_mm - st.min_x_mm, 480 / kPpm + 1);
  // The first block is the fill colour's; its first stitch lies in the disk or the rectangle.
  size_t first_stitch = 0;
  while (plan.points[first_stitch].kind != StitchKind::stitch) ++first_stitch;
  const double fx = plan.points[first_stitch].x_mm * kPpm + 239.5, fy = plan.points[first_stitch].y_mm * kPpm + 199.5;
  EXPECT_TRUE(cv::norm(cv::Point2d(fx, fy) - cv::Point2d(110, 120)) < 82 || (fx > 298 && fy > 248));
}

TEST(EmbroideryStitches, ThreadIsLockedAtEveryStartAndCut) {
  const Segmentation seg = drawn_design();
  const StitchPlan plan = plan_stitches(seg, std::vector<double>(seg.regions.size(), 0.5), params8());
  const auto& pts = plan.points;
  auto same = [](const StitchPoint& a, const StitchPoint& b) { return std::hypot(a.x_mm - b.x_mm, a.y_mm - b.y_mm) < 1e-9; };
  int ties = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    const StitchKind k = pts[i].kind;
    if (k == StitchKind::trim || k == StitchKind::color_change || k == StitchKind::end) {
      if (i >= 1 && pts[i - 1].kind != StitchKind::stitch) continue;  // a colour change right after its trim
      ASSERT_GE(i, 3u);
      // ... a, b, a, cut: back along the last stitch and return.
      EXPECT_TRUE(same(pts[i - 1], pts[i - 3]) && pts[i - 2].kind == StitchKind::stitch) << "no tie-off at " << i;
      EXPECT_LE(std::hypot(pts[i - 1].x_mm - pts[i - 2].x_mm, pts[i - 1].y_mm - pts[i - 2].y_mm), 0.5 + 1e-9);
      ++ties;
    }
    if (k == StitchKind::jump && i + 3 < pts.size() && pts[i + 1].kind == StitchKind::stitch) {
      // jump to a, a, b, a: ahead along the next stitch and return.
      EXPECT_TRUE(same(pts[i + 1], pts[i]) && same(pts[i + 3], pts[i + 1])) << "no tie-in at " << i;
      ++ties;
    }
  }
  EXPECT_GE(ties, 2 * (stitch_stats(plan).trims + 1));
}

TEST(EmbroideryStitches, PlanCoversEveryRegion) {
  const Segmentation seg = drawn_design();
  const StitchParams p = params8();
  const StitchPlan plan = plan_stitches(seg, std::vector<double>(seg.regions.size(), 0.5), p);
  cv::Mat1b sewn(seg.size, uchar(0));
  const cv::Point2d centre(239.5, 199.5);
  for (size_t i = 1; i < plan.points.size(); ++i) {
    const auto& a = plan.points[i - 1];
    const auto& b = plan.points[i];
    if (b.kind != StitchKind::stitch || !is_positioned(a.kind)) continue;
    // 3 px: a thread is about 0.4 mm wide
    cv::line(sewn, cv::Point2d(a.x_mm, a.y_mm) * kPpm + centre, cv::Point2d(b.x_mm, b.y_mm) * kPpm + centre, 255, 3);
  }
  for (const Region& r : seg.regions) {
    cv::Mat1b full(seg.size, uchar(0));
    r.mask.copyTo(full(r.bbox));
    EXPECT_GE(coverage(full, sewn), 0.9) << "region " << r.id << " (" << style_name(r.style) << ")";
  }
}

TEST(EmbroideryStitches, DesignLargerThanTheHoopFails) {
  const Segmentation seg = drawn_design();
  StitchParams p = params8();
  const StitchStats st = stitch_stats(plan_stitches(seg, std::vector<double>(seg.regions.size(), 0.5), p));
  p.hoop_width_mm = 40;
  p.hoop_height_mm = 30;
  char expected[160];
  std::snprintf(expected, sizeof expected, "design is %.1f x %.1f mm, the hoop is 40.0 x 30.0 mm",
                st.max_x_mm - st.min_x_mm, st.max_y_mm - st.min_y_mm);
  try {
    plan_stitches(seg, std::vector<double>(seg.regions.size(), 0.5), p);
    FAIL() << "no HoopTooSmall";
  } catch (const HoopTooSmall& e) {
    EXPECT_EQ(std::string(e.what()), expected);
  }
}

TEST(EmbroideryStitches, PlanRejectsMismatchedDirections) {
  const Segmentation seg = drawn_design();
  EXPECT_THROW(plan_stitches(seg, {0.0}, params8()), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::embroidery
