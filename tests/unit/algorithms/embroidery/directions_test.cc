// Stitch directions of regions (algorithms/embroidery/directions.h): a long-short region takes
// its neighbours' direction, a lone rectangle its long axis.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <vector>

#include "algorithms/embroidery/directions.h"
#include "tests/unit/algorithms/embroidery/synthesis_fixture.h"

namespace atelier::embroidery {
namespace {

using test::kPi;
using test::make_seg;

TEST(EmbroiderySynthesis, LongShortTakesItsNeighboursDirection) {
  // A long-short band whose long axis runs at 120 deg; edge lines at 30 deg close its ends.
  cv::Mat1i labels(400, 400, -1);
  const double a = 120 * kPi / 180;
  const cv::RotatedRect band(cv::Point2f(200, 200), cv::Size2f(240, 70), 120);
  cv::Point2f c[4];
  band.points(c);
  std::vector<cv::Point> poly(c, c + 4);
  cv::fillConvexPoly(labels, poly, 0);
  const cv::Point2f along(static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)));
  const cv::Point2f across(static_cast<float>(std::cos(a - kPi / 2)), static_cast<float>(std::sin(a - kPi / 2)));
  for (int end : {-1, 1}) {
    const cv::Point2f mid = cv::Point2f(200, 200) + along * static_cast<float>(end * 122);
    cv::line(labels, mid - across * 50.f, mid + across * 50.f, end < 0 ? 1 : 2, 3);
  }
  const Segmentation seg =
      make_seg(labels, {{90, 90, 90}, {10, 10, 10}, {10, 10, 10}}, {Style::long_short, Style::edge, Style::edge});
  const std::vector<double> dir = region_directions(seg);
  auto axis_diff = [](double x, double y) {
    double d = std::fmod(std::abs(x - y), kPi);
    return std::min(d, kPi - d);
  };
  EXPECT_LT(axis_diff(dir[1], 30 * kPi / 180), 5 * kPi / 180);
  EXPECT_LT(axis_diff(dir[0], 30 * kPi / 180), 5 * kPi / 180);
}

TEST(EmbroiderySynthesis, LoneRectangleTakesItsLongAxis) {
  cv::Mat1i labels(300, 300, -1);
  const cv::RotatedRect rect(cv::Point2f(150, 150), cv::Size2f(200, 60), 20);
  cv::Point2f c[4];
  rect.points(c);
  std::vector<cv::Point> poly(c, c + 4);
  cv::fillConvexPoly(labels, poly, 0);
  const Segmentation seg = make_seg(labels, {{90, 90, 90}}, {Style::long_short});
  const double d = region_directions(seg)[0];
  EXPECT_NEAR(d, 20 * kPi / 180, 3 * kPi / 180);
}

}  // namespace
}  // namespace atelier::embroidery
