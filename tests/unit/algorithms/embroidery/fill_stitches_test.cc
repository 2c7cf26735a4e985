// Tatami fill (algorithms/embroidery/fill_stitches.h): covers drawn regions and stays inside
// them, leaves holes empty, staggers its rows.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <map>
#include <vector>

#include "algorithms/embroidery/fill_stitches.h"
#include "tests/unit/algorithms/embroidery/stitches_fixture.h"

namespace atelier::embroidery {
namespace {

using test::coverage;
using test::expect_long_jumps_trimmed;
using test::kPpm;
using test::params8;
using test::rasterise;
using test::stitch_lengths;
using test::to_px;
using test::worst_outside;

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

// Issue 21 point 5: a fill stitch of exactly fill_max_stitch_mm between two grid points came
// out as two collinear halves (float32 points and ceil(d / max - 1e-9)): twice the needle
// drops and a broken stagger. On a large rectangle, along every row, no two consecutive
// stitches are collinear with a sum within the maximum, and a row of length W has about
// W / max needle points.
void expect_no_split_stitches(double angle) {
  SCOPED_TRACE(angle);
  const cv::Mat1b m(480, 640, uchar(255));  // 80 x 60 mm
  StitchParams p = params8();
  p.fill_underlay = false;
  const std::vector<cv::Point2f> px = to_px(fill_region(m, {0, 0}, angle, p));
  ASSERT_GT(px.size(), 1000u);
  const cv::Point2f along(static_cast<float>(std::cos(angle)), static_cast<float>(std::sin(angle)));
  const cv::Point2f across(-along.y, along.x);
  const double max_px = p.fill_max_stitch_mm * kPpm;
  int along_row = 0, split = 0;
  for (size_t i = 0; i + 2 < px.size(); ++i) {
    const cv::Point2f a = px[i], b = px[i + 1], c = px[i + 2];
    const double ab = cv::norm(b - a), bc = cv::norm(c - b);
    // Two stitches along one row, in the same direction.
    if (std::abs((b - a).dot(across)) > 0.05 || std::abs((c - b).dot(across)) > 0.05) continue;
    if (ab < 1e-3 || bc < 1e-3 || (b - a).dot(c - b) <= 0) continue;
    // Away from the border: at the corners, travel between sections may continue a row's line.
    if (b.x < 16 || b.y < 16 || b.x > m.cols - 17 || b.y > m.rows - 17) continue;
    ++along_row;
    if (ab + bc <= max_px + 1e-3) ++split;
  }
  EXPECT_GT(along_row, 500);
  EXPECT_EQ(split, 0) << "of " << along_row << " pairs of stitches along a row";
  // Needle drops per row: the row's length / max, plus its two ends and the step from the
  // previous row and to the next (-1 .. +5 for where the stagger puts the first grid point).
  struct Row {
    int n = 0;
    double lo = 1e9, hi = -1e9;
  };
  std::map<long, Row> rows;
  const double v0 = px[0].dot(across);
  for (const cv::Point2f& q : px) {
    Row& r = rows[std::lround((q.dot(across) - v0) / (p.fill_row_spacing_mm * kPpm))];
    ++r.n;
    r.lo = std::min(r.lo, static_cast<double>(q.dot(along)));
    r.hi = std::max(r.hi, static_cast<double>(q.dot(along)));
  }
  int checked = 0;
  for (const auto& [k, r] : rows) {
    const double len = r.hi - r.lo;
    if (len < 10 * max_px) continue;  // short corner rows: their ends dominate
    ++checked;
    EXPECT_GE(r.n, len / max_px - 1) << "row " << k << " of " << len << " px";
    EXPECT_LE(r.n, len / max_px + 5) << "row " << k << " of " << len << " px";
  }
  EXPECT_GT(checked, 20);
}

TEST(EmbroideryStitches, FillStitchesAreNotSplitInHalves) {
  expect_no_split_stitches(0.0);
  expect_no_split_stitches(CV_PI / 6);
}

}  // namespace
}  // namespace atelier::embroidery
