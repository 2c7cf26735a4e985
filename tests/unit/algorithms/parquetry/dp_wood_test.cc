// The wood refine = dp's cuts may use beyond each core: the core always, free wood around it
// where no other piece (of the plan or the stock) needs it, never off the veneer, and never
// so that two pieces sharing a sheet could come within the kerf of each other.
#include <gtest/gtest.h>

#include <cmath>

#include "algorithms/parquetry/dp_wood.h"

namespace atelier::parquetry {
namespace {

constexpr double kPxPerMm = 1.0;  // a 25.4 dpi scan: 1 px = 1 mm
constexpr double kKerfMm = 0.2;

// A dp cell whose 28 px window holds a 20 px core 4 px in, its window's top-left at `pos` on
// the sheet (rotation 0).
Placed cell_at(cv::Point pos) {
  Placed p;
  p.rect = cv::Rect(0, 0, 28, 28);
  p.core = cv::Rect(4, 4, 20, 20);
  p.match.copy = 0;
  p.match.sheet = 0;
  p.match.pos = pos;
  p.match.size = p.rect.size();
  return p;
}

TEST(ParquetryDpWood, OwnCoreAlwaysFreeWoodAroundItNeverAnothersNorOffTheSheet) {
  Sheet sheet;
  sheet.id = "maple";
  sheet.image = cv::Mat(100, 100, CV_8UC3, cv::Scalar(90, 140, 200));
  sheet.dpi = 25.4;
  Stock stock;  // a piece of an earlier job just below A
  stock.used["maple"].push_back({"job-0", 1, {{14, 37}, {34, 37}, {34, 47}, {14, 47}}});
  const WoodIndex wood({sheet}, stock, kPxPerMm, 1, 0.5, 0.5, kKerfMm);
  const Placed a = cell_at({10, 10});   // core on the sheet at x 14..34, y 14..34
  const Placed b = cell_at({31, 10});   // core at x 35..55: 1 mm right of A's
  const Placed c = cell_at({-4, 60});   // core at x 0..20, on the sheet's left edge
  const std::vector<cv::Mat> avail = available_wood({&a, &b, &c}, {sheet}, stock, wood, kPxPerMm, kKerfMm);
  ASSERT_EQ(avail.size(), 3u);
  for (const cv::Mat& m : avail) {
    ASSERT_EQ(m.size(), cv::Size(28, 28));
    EXPECT_EQ(cv::countNonZero(m(cv::Rect(4, 4, 20, 20))), 400);  // the core
  }
  EXPECT_TRUE(avail[0].at<uchar>(16, 1));    // A's left margin: free wood, nobody near
  EXPECT_FALSE(avail[0].at<uchar>(16, 25));  // A's right margin: B's core is there
  EXPECT_FALSE(avail[1].at<uchar>(16, 2));   // B's left margin: A's core
  EXPECT_FALSE(avail[0].at<uchar>(26, 12));  // A's bottom margin: the stock's piece + kerf
  EXPECT_TRUE(avail[0].at<uchar>(24, 12));   // ... but not yet its first row
  EXPECT_FALSE(avail[2].at<uchar>(16, 2));   // C's left margin: off the sheet
  EXPECT_TRUE(avail[2].at<uchar>(16, 26));   // C's right margin: free

  // Wood given to A and to B (beyond their cores) stays a kerf and a pixel apart.
  auto sheet_points = [](const Placed& p, const cv::Mat& m, bool margin_only) {
    std::vector<cv::Point2d> out;
    for (int y = 0; y < m.rows; ++y)
      for (int x = 0; x < m.cols; ++x)
        if (m.at<uchar>(y, x) && !(margin_only && p.core.contains({x, y}))) out.emplace_back(p.match.pos.x + x + 0.5, p.match.pos.y + y + 0.5);
    return out;
  };
  const auto a_margin = sheet_points(a, avail[0], true), b_all = sheet_points(b, avail[1], false);
  const auto b_margin = sheet_points(b, avail[1], true), a_all = sheet_points(a, avail[0], false);
  double closest = 1e9;
  for (const auto& p : a_margin) for (const auto& q : b_all) closest = std::min(closest, cv::norm(p - q));
  for (const auto& p : b_margin) for (const auto& q : a_all) closest = std::min(closest, cv::norm(p - q));
  EXPECT_GE(closest, kKerfMm * kPxPerMm + 1.0);
}

}  // namespace
}  // namespace atelier::parquetry
