// Geometry under the laser planner: Bezier flattening, nesting, kerf offset, path order.
#include <gtest/gtest.h>

#include <cmath>

#include "algorithms/laser/geometry.h"
#include "algorithms/laser/kerf.h"
#include "algorithms/laser/nesting.h"
#include "algorithms/laser/order.h"
#include "tests/support/laser_test_shapes.h"

namespace atelier::laser {
namespace {

using testing::square;
using testing::width_of;

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

TEST(LaserGeometry, NestingFindsContainers) {
  std::vector<Path> paths{square(0, 0, 100), square(10, 10, 30), square(15, 15, 5),
                          square(60, 60, 10), Path{{{70, 20}, {80, 30}}, false}};
  auto c = containing_paths(paths);
  EXPECT_TRUE(c[0].empty());
  EXPECT_EQ(c[1], std::vector<size_t>{0});
  EXPECT_EQ(c[2], (std::vector<size_t>{0, 1}));
  EXPECT_EQ(c[3], std::vector<size_t>{0});
  EXPECT_EQ(c[4], std::vector<size_t>{0}) << "an open path inside a shape belongs to it";
}

TEST(LaserGeometry, DuplicatesDoNotContainEachOther) {
  auto c = containing_paths({square(0, 0, 10), square(0, 0, 10)});
  EXPECT_TRUE(c[0].empty());
  EXPECT_TRUE(c[1].empty());
}

TEST(LaserKerf, OuterGrowsHoleShrinks) {
  KerfResult r = apply_kerf({square(0, 0, 20), square(5, 5, 10)}, 0.3);
  ASSERT_EQ(r.paths.size(), 2u);
  EXPECT_NEAR(width_of(r.paths[0]), 20.3, 0.002);
  EXPECT_NEAR(width_of(r.paths[1]), 9.7, 0.002);
  EXPECT_EQ(r.vanished_holes, 0u);
  // A piece inside the hole (depth 2) is an outer boundary again: it grows.
  KerfResult r2 = apply_kerf({square(0, 0, 40), square(5, 5, 30), square(10, 10, 10)}, 0.4);
  ASSERT_EQ(r2.paths.size(), 3u);
  EXPECT_NEAR(width_of(r2.paths[2]), 10.4, 0.002);
}

TEST(LaserKerf, HoleSmallerThanKerfVanishes) {
  KerfResult r = apply_kerf({square(0, 0, 20), square(5, 5, 0.5)}, 1.0);
  ASSERT_EQ(r.paths.size(), 1u);
  EXPECT_EQ(r.vanished_holes, 1u);
}

TEST(LaserKerf, OpenPathsAndZeroKerfUnchanged) {
  Path line{{{0, 0}, {10, 0}}, false};
  KerfResult r = apply_kerf({line, square(20, 0, 5)}, 0);
  ASSERT_EQ(r.paths.size(), 2u);
  EXPECT_NEAR(width_of(r.paths[1]), 5, 1e-12);
  KerfResult r2 = apply_kerf({line}, 0.5);
  ASSERT_EQ(r2.paths.size(), 1u);
  EXPECT_EQ(r2.paths[0].points.size(), 2u);
  EXPECT_DOUBLE_EQ(r2.paths[0].points[1].x, 10);
}

TEST(LaserOrder, InnerBeforeOuterEvenWhenOuterIsNearer) {
  Point head{0, 0};
  auto out = order_paths({square(0, 0, 100), square(40, 40, 10)}, head);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NEAR(width_of(out[0]), 10, 1e-12);
  EXPECT_NEAR(width_of(out[1]), 100, 1e-12);
  EXPECT_DOUBLE_EQ(out[1].points.front().x, 0) << "outer entered at its vertex nearest (40,40)";
  EXPECT_DOUBLE_EQ(head.x, out[1].points.front().x);
}

TEST(LaserOrder, OpenPathReversedWhenItsEndIsNearer) {
  Point head{0, 0};
  auto out = order_paths({Path{{{100, 100}, {10, 10}}, false}}, head);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_DOUBLE_EQ(out[0].points.front().x, 10);
  EXPECT_DOUBLE_EQ(head.x, 100);
}

}  // namespace
}  // namespace atelier::laser
