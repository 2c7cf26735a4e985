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

}  // namespace
}  // namespace atelier::embroidery
