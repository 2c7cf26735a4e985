// The stitch planner (algorithms/embroidery/stitch_planner.h): colour blocks, trims, ties, hidden
// travel, no tiny stitches,
// end code, stitch lengths, coverage of every region and the hoop check.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "algorithms/embroidery/pipeline.h"
#include "algorithms/embroidery/stitch_planner.h"
#include "algorithms/embroidery/textures.h"
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

// Every run of thread (from a jump to the next trim, colour change or the end) starts with a
// tie-in and ends with a tie-off, Ink/Stitch's default lock: four stitches of at most
// 0.75 mm (and more than min_stitch_mm) that come back to where they started (issue 21
// point 8; it was one 0.5 mm back-stitch, and a one-stitch run could have none).
void expect_every_run_tied(const StitchPlan& plan, double min_stitch_mm) {
  const auto& pts = plan.points;
  auto dist = [&](size_t i, size_t j) { return std::hypot(pts[i].x_mm - pts[j].x_mm, pts[i].y_mm - pts[j].y_mm); };
  int runs = 0;
  for (size_t j = 0; j < pts.size(); ++j) {
    if (pts[j].kind != StitchKind::jump) continue;
    size_t k = j + 1;
    while (k < pts.size() && pts[k].kind == StitchKind::stitch) ++k;
    if (k == j + 1) continue;  // a long jump split in several
    ++runs;
    ASSERT_GE(k - j - 1, 9u) << "a run of " << k - j - 1 << " stitches at " << j << " cannot hold two ties";
    // Tie-in: jump to h, then four stitches ending at h.
    EXPECT_LT(dist(j + 4, j), 1e-9) << "no tie-in after the jump at " << j;
    for (size_t t = j + 1; t <= j + 4; ++t) {
      EXPECT_LE(dist(t, t - 1), 0.75 + 1e-9) << "tie-in stitch at " << t;
      EXPECT_GT(dist(t, t - 1), min_stitch_mm) << "tie-in stitch at " << t;
    }
    // Tie-off: e, then four stitches ending at e, then the cut.
    EXPECT_LT(dist(k - 1, k - 5), 1e-9) << "no tie-off before " << k;
    for (size_t t = k - 4; t < k; ++t) {
      EXPECT_LE(dist(t, t - 1), 0.75 + 1e-9) << "tie-off stitch at " << t;
      EXPECT_GT(dist(t, t - 1), min_stitch_mm) << "tie-off stitch at " << t;
    }
    EXPECT_TRUE(k < pts.size() && (pts[k].kind == StitchKind::trim || pts[k].kind == StitchKind::end))
        << "run at " << j << " not ended by a trim or the end";
  }
  EXPECT_EQ(runs, stitch_stats(plan).trims + 1);
}

TEST(EmbroideryStitches, ThreadIsLockedAtEveryStartAndCut) {
  const Segmentation seg = drawn_design();
  const StitchParams p = params8();
  const StitchPlan plan = plan_stitches(seg, std::vector<double>(seg.regions.size(), 0.5), p);
  expect_every_run_tied(plan, p.min_stitch_mm);
}

// Issue 21 point 6: many small regions of one colour, under a covering layer of a colour sewn
// after them. Travel between them runs under the later colour instead of being trimmed; over
// bare fabric it never runs further than trim_jump_mm without a trim.
struct Patches {
  Segmentation seg;
  cv::Mat1i colour_px;  // palette index per pixel, -1 = fabric
};

Patches patches_under_cover(bool with_cover) {
  Patches d;
  Segmentation& seg = d.seg;
  seg.size = {480, 480};  // 60 x 60 mm
  seg.palette.bgr = {{40, 40, 200}, {200, 200, 40}};
  cv::Mat1b cover(seg.size, uchar(0));
  cv::rectangle(cover, cv::Rect(20, 20, 440, 440), 255, cv::FILLED);
  d.colour_px = cv::Mat1i(seg.size, -1);
  for (int gy = 0; gy < 6; ++gy)
    for (int gx = 0; gx < 6; ++gx) {  // 36 squares of 2 x 2 mm, 10 mm apart
      cv::Mat1b sq(seg.size, uchar(0));
      const cv::Rect r(50 + gx * 72, 50 + gy * 72, 16, 16);
      cv::rectangle(sq, r, 255, cv::FILLED);
      cover(r).setTo(0);
      seg.regions.push_back(region_from(sq, 0, Style::long_short));
      d.colour_px(r).setTo(0);
    }
  if (with_cover) {
    seg.regions.push_back(region_from(cover, 1, Style::long_short));
    d.colour_px.setTo(1, cover);
  }
  for (size_t i = 0; i < seg.regions.size(); ++i) seg.regions[i].id = static_cast<int>(i);
  return d;
}

// The longest stretch (mm) of any one stitch over fabric pixels.
double longest_over_fabric(const StitchPlan& plan, const cv::Mat1i& colour_px) {
  const cv::Point2d centre((colour_px.cols - 1) / 2.0, (colour_px.rows - 1) / 2.0);
  double worst = 0;
  const StitchPoint* prev = nullptr;
  for (const StitchPoint& q : plan.points) {
    if (!is_positioned(q.kind)) continue;
    if (prev && q.kind == StitchKind::stitch) {
      const cv::Point2d a = cv::Point2d(prev->x_mm, prev->y_mm) * kPpm + centre, b = cv::Point2d(q.x_mm, q.y_mm) * kPpm + centre;
      const int steps = std::max(1, static_cast<int>(std::ceil(cv::norm(b - a) * 4)));  // 0.25 px
      int bare = 0;
      for (int t = 0; t < steps; ++t) {
        const cv::Point2d m = a + (b - a) * ((t + 0.5) / steps);
        const int x = cvRound(m.x), y = cvRound(m.y);
        if (x < 0 || y < 0 || x >= colour_px.cols || y >= colour_px.rows || colour_px(y, x) < 0) ++bare;
      }
      worst = std::max(worst, cv::norm(b - a) / kPpm * bare / steps);
    }
    prev = &q;
  }
  return worst;
}

TEST(EmbroideryStitches, TravelRunsUnderThreadStillToComeInsteadOfTrims) {
  const Patches d = patches_under_cover(true);
  const StitchParams p = params8();
  const StitchPlan plan = plan_stitches(d.seg, std::vector<double>(d.seg.regions.size(), 0.3), p);
  const StitchStats st = stitch_stats(plan);
  EXPECT_EQ(st.color_changes, 1);
  // 36 squares 7 mm apart: each was a trim; under the cover none is needed.
  EXPECT_LE(st.trims, 1 + 3) << "trims for 36 small regions";
  std::printf("36 squares under a later colour: %d trims (1 for the colour change)\n", st.trims);
  expect_every_run_tied(plan, p.min_stitch_mm);
  expect_long_jumps_trimmed(plan.points, p.trim_jump_mm);
  EXPECT_LE(longest_over_fabric(plan, d.colour_px), p.trim_jump_mm + 1e-6);
}

TEST(EmbroideryStitches, TravelOverBareFabricIsTrimmed) {
  const Patches d = patches_under_cover(false);  // the same squares on bare fabric
  const StitchParams p = params8();
  const StitchPlan plan = plan_stitches(d.seg, std::vector<double>(d.seg.regions.size(), 0.3), p);
  EXPECT_EQ(stitch_stats(plan).trims, 35);  // nothing hides the 7 mm between them
  expect_every_run_tied(plan, p.min_stitch_mm);
  EXPECT_LE(longest_over_fabric(plan, d.colour_px), p.trim_jump_mm + 1e-6);
}

// Issue 21 point 7: a real design had hundreds of stitches of 0.1 mm or less (fill rows one
// pixel apart at their ends, satin tips, the stitch in place after every jump); none is
// left, tie stitches included.
TEST(EmbroideryStitches, NoStitchOfTheMinimumLengthOrLessOnARealImage) {
  const cv::Mat img = cv::imread(std::string(ATELIER_TEST_DATA) + "/fruits.jpg", cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty());
  DesignParams dp;  // 90 mm wide, as a job makes it
  const Design d = make_design(img, procedural_textures(), dp);
  int tiny = 0, n = 0;
  for (double l : stitch_lengths(d.plan.points)) {
    ++n;
    if (l <= dp.stitches.min_stitch_mm + 1e-9) ++tiny;
  }
  // And as the files write them: positions rounded to 0.1 mm.
  int tiny_in_file = 0;
  const StitchPoint* prev = nullptr;
  for (const StitchPoint& q : d.plan.points) {
    if (!is_positioned(q.kind)) continue;
    if (prev && q.kind == StitchKind::stitch) {
      const FileUnits a = to_file_units(*prev), b = to_file_units(q);
      if (std::hypot(static_cast<double>(b.x - a.x), static_cast<double>(b.y - a.y)) <= 1.0) ++tiny_in_file;
    }
    prev = &q;
  }
  EXPECT_GT(n, 10000);
  EXPECT_EQ(tiny, 0) << "of " << n << " stitches";
  EXPECT_EQ(tiny_in_file, 0) << "of " << n << " stitches, in 0.1 mm file units";
  expect_every_run_tied(d.plan, dp.stitches.min_stitch_mm);
  const StitchStats st = stitch_stats(d.plan);
  std::printf("fruits.jpg at %.0f mm: %d stitches, %d trims, %d colour changes\n", d.width_mm, st.stitches, st.trims,
              st.color_changes);
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
