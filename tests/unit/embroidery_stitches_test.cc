// Machine stitches from regions (issue 6 part 2): tatami fill covers drawn regions and stays
// inside them, rows are staggered, satin stitches go across the column and wide columns are
// split, edges get running stitches no longer than asked; the planner's colour changes, trims,
// end code, stitch lengths and hoop check.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "algorithms/embroidery/fill_stitches.h"
#include "algorithms/embroidery/running_stitches.h"
#include "algorithms/embroidery/satin_stitches.h"
#include "algorithms/embroidery/stitch_planner.h"

namespace atelier::embroidery {
namespace {

constexpr double kPpm = 8;  // test images: 8 px per mm

StitchParams params8() {
  StitchParams p;
  p.px_per_mm = kPpm;
  p.hoop_width_mm = p.hoop_height_mm = 200;
  return p;
}

// Stitch points back in mask pixels (region-level functions get offset 0).
std::vector<cv::Point2f> to_px(const std::vector<StitchPoint>& pts, StitchKind kind = StitchKind::stitch) {
  std::vector<cv::Point2f> out;
  for (const StitchPoint& p : pts)
    if (p.kind == kind) out.emplace_back(static_cast<float>(p.x_mm * kPpm), static_cast<float>(p.y_mm * kPpm));
  return out;
}

// The thread laid between consecutive needle penetrations, drawn `thickness` px wide.
cv::Mat1b rasterise(const std::vector<StitchPoint>& pts, cv::Size size, int thickness) {
  cv::Mat1b canvas(size, uchar(0));
  const int shift = 4;
  auto fx = [&](double mm) { return static_cast<int>(std::lround(mm * kPpm * (1 << shift))); };
  for (size_t i = 1; i < pts.size(); ++i) {
    if (pts[i].kind != StitchKind::stitch || !is_positioned(pts[i - 1].kind)) continue;
    cv::line(canvas, {fx(pts[i - 1].x_mm), fx(pts[i - 1].y_mm)}, {fx(pts[i].x_mm), fx(pts[i].y_mm)}, 255, thickness,
             cv::LINE_8, shift);
  }
  return canvas;
}

double coverage(const cv::Mat1b& mask, const cv::Mat1b& sewn) {
  return static_cast<double>(cv::countNonZero(mask & sewn)) / cv::countNonZero(mask);
}

// Largest distance (px) from a needle point to the nearest mask pixel centre (1e9 when none
// is within 8 px).
double worst_outside(const cv::Mat1b& mask, const std::vector<StitchPoint>& pts) {
  double worst = 0;
  for (const cv::Point2f& p : to_px(pts)) {
    double nearest = 1e9;
    for (int y = cvFloor(p.y) - 8; y <= cvCeil(p.y) + 8; ++y)
      for (int x = cvFloor(p.x) - 8; x <= cvCeil(p.x) + 8; ++x)
        if (x >= 0 && y >= 0 && x < mask.cols && y < mask.rows && mask(y, x))
          nearest = std::min(nearest, cv::norm(p - cv::Point2f(x, y)));
    worst = std::max(worst, nearest);
  }
  return worst;
}

// Length (mm) of each stitch: consecutive positioned points where the second is a stitch.
std::vector<double> stitch_lengths(const std::vector<StitchPoint>& pts) {
  std::vector<double> out;
  const StitchPoint* prev = nullptr;
  for (const StitchPoint& p : pts) {
    if (!is_positioned(p.kind)) continue;
    if (prev && p.kind == StitchKind::stitch) out.push_back(std::hypot(p.x_mm - prev->x_mm, p.y_mm - prev->y_mm));
    prev = &p;
  }
  return out;
}

// Every run of jumps longer than trim_jump_mm in total starts right after a trim (or after a
// colour change that follows a trim); the very first move from the machine's start is exempt.
void expect_long_jumps_trimmed(const std::vector<StitchPoint>& pts, double trim_jump_mm) {
  const StitchPoint* last_pos = nullptr;
  bool started = false;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (pts[i].kind != StitchKind::jump) {
      if (pts[i].kind == StitchKind::stitch) started = true;
      if (is_positioned(pts[i].kind)) last_pos = &pts[i];
      continue;
    }
    size_t j = i;
    double len = 0;
    const StitchPoint* from = last_pos;
    while (j < pts.size() && pts[j].kind == StitchKind::jump) {
      if (from) len += std::hypot(pts[j].x_mm - from->x_mm, pts[j].y_mm - from->y_mm);
      from = &pts[j];
      ++j;
    }
    if (started && len > trim_jump_mm) {
      ASSERT_GT(i, 0u);
      const StitchKind before = pts[i - 1].kind;
      const bool trimmed = before == StitchKind::trim ||
                           (before == StitchKind::color_change && i >= 2 && pts[i - 2].kind == StitchKind::trim);
      EXPECT_TRUE(trimmed) << "untrimmed jump of " << len << " mm at point " << i;
    }
    last_pos = from;
    i = j - 1;
  }
}

cv::Mat1b disk_with_hole() {
  cv::Mat1b m(240, 240, uchar(0));
  cv::circle(m, {120, 120}, 100, 255, cv::FILLED);
  cv::circle(m, {120, 120}, 40, 0, cv::FILLED);
  return m;
}
cv::Mat1b l_shape() {
  cv::Mat1b m(240, 240, uchar(0));
  cv::rectangle(m, cv::Rect(20, 20, 60, 200), 255, cv::FILLED);
  cv::rectangle(m, cv::Rect(20, 160, 200, 60), 255, cv::FILLED);
  return m;
}
cv::Mat1b blobs_with_neck() {
  cv::Mat1b m(200, 360, uchar(0));
  cv::circle(m, {70, 100}, 55, 255, cv::FILLED);
  cv::circle(m, {290, 100}, 55, 255, cv::FILLED);
  cv::line(m, {70, 100}, {290, 100}, 255, 6);
  return m;
}

void expect_fill_covers(const cv::Mat1b& mask, double angle, const char* what) {
  SCOPED_TRACE(what);
  const StitchParams p = params8();
  const std::vector<StitchPoint> pts = fill_region(mask, {0, 0}, angle, p);
  ASSERT_FALSE(pts.empty());
  const int thickness = static_cast<int>(std::ceil(p.fill_row_spacing_mm * kPpm));
  EXPECT_GE(coverage(mask, rasterise(pts, mask.size(), thickness)), 0.95);
  EXPECT_LE(worst_outside(mask, pts), 1.0);
  for (double l : stitch_lengths(pts)) ASSERT_LE(l, p.fill_max_stitch_mm + 1e-6);
  expect_long_jumps_trimmed(pts, p.trim_jump_mm);
}

TEST(EmbroideryStitches, FillCoversADiskWithAHole) { expect_fill_covers(disk_with_hole(), 0.3, "disk with hole"); }
TEST(EmbroideryStitches, FillCoversAnLShape) { expect_fill_covers(l_shape(), 2.0, "L"); }
TEST(EmbroideryStitches, FillCoversTwoBlobsJoinedByANeck) {
  expect_fill_covers(blobs_with_neck(), CV_PI / 2, "blobs, rows across the neck");
  expect_fill_covers(blobs_with_neck(), 0.0, "blobs, rows along the neck");
}

TEST(EmbroideryStitches, FillLeavesTheHoleEmpty) {
  const cv::Mat1b m = disk_with_hole();
  const auto pts = fill_region(m, {0, 0}, 0.3, params8());
  // Nothing sewn in the hole: the thread never crosses it (a 2 px margin for line width).
  cv::Mat1b hole(m.size(), uchar(0));
  cv::circle(hole, {120, 120}, 37, 255, cv::FILLED);
  EXPECT_EQ(cv::countNonZero(hole & rasterise(pts, m.size(), 1)), 0);
}

TEST(EmbroideryStitches, FillRowsAreStaggered) {
  cv::Mat1b m(200, 200, uchar(255));
  StitchParams p = params8();
  p.fill_underlay = false;
  const auto pts = fill_region(m, {0, 0}, 0.0, p);
  // Needle points inside the rows (away from the ends), grouped by row.
  std::map<long, std::vector<double>> rows;
  for (const cv::Point2f& q : to_px(pts))
    if (q.x > 20 && q.x < 180) rows[std::lround(q.y)].push_back(q.x);
  ASSERT_GT(rows.size(), 50u);
  int aligned = 0, pairs = 0;
  for (auto it = rows.begin(); std::next(it) != rows.end(); ++it) {
    const auto& a = it->second;
    const auto& b = std::next(it)->second;
    ++pairs;
    for (double x : a)
      for (double y : b)
        if (std::abs(x - y) < 0.5) ++aligned;
  }
  EXPECT_GT(pairs, 50);
  EXPECT_EQ(aligned, 0) << "needle points of neighbouring rows line up";
}

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
