// Geometry under the laser planner (algorithms/laser/geometry.h): Bezier flattening.
#include <gtest/gtest.h>

#include <cmath>

#include "algorithms/laser/geometry.h"

namespace atelier::laser {
namespace {

Point cubic_at(Point p0, Point p1, Point p2, Point p3, double t) {
  double u = 1 - t;
  double a = u * u * u, b = 3 * u * u * t, c = 3 * u * t * t, d = t * t * t;
  return {a * p0.x + b * p1.x + c * p2.x + d * p3.x, a * p0.y + b * p1.y + c * p2.y + d * p3.y};
}

double distance_to_polyline(Point p, const std::vector<Point>& line) {
  double best = 1e300;
  for (size_t i = 1; i < line.size(); ++i)
    best = std::min(best, distance_to_segment(p, line[i - 1], line[i]));
  return best;
}

TEST(LaserGeometry, FlattenedCubicStaysWithinTolerance) {
  const Point p0{0, 0}, p1{10, 40}, p2{60, -30}, p3{50, 10};
  for (double tol : {0.5, 0.05, 0.01}) {
    std::vector<Point> out{p0};
    flatten_cubic(p0, p1, p2, p3, tol, out);
    ASSERT_GE(out.size(), 3u);
    EXPECT_DOUBLE_EQ(out.back().x, p3.x);
    EXPECT_DOUBLE_EQ(out.back().y, p3.y);
    double worst = 0;
    for (int i = 0; i <= 2000; ++i)
      worst = std::max(worst, distance_to_polyline(cubic_at(p0, p1, p2, p3, i / 2000.0), out));
    EXPECT_LE(worst, tol) << "tolerance " << tol << " with " << out.size() << " points";
  }
  std::vector<Point> coarse, fine;
  flatten_cubic(p0, p1, p2, p3, 0.5, coarse);
  flatten_cubic(p0, p1, p2, p3, 0.01, fine);
  EXPECT_LT(coarse.size() * 3, fine.size()) << "a finer tolerance needs more points";
}

TEST(LaserGeometry, StraightCubicIsOneSegment) {
  std::vector<Point> out;
  flatten_cubic({0, 0}, {1, 1}, {2, 2}, {3, 3}, 0.01, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_DOUBLE_EQ(out[0].x, 3);
}

}  // namespace
}  // namespace atelier::laser
