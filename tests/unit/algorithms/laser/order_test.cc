// The cutting order of laser paths (algorithms/laser/order.h): inner before outer, open paths
// reversed when nearer.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <algorithm>
#include <random>

#include "algorithms/laser/nesting.h"
#include "algorithms/laser/order.h"
#include "tests/support/laser_test_shapes.h"

namespace atelier::laser {
namespace {

using testing::square;
using testing::width_of;

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

// The order as a plain scan of every allowed path chooses it (the planner before its spatial
// index, quadratic): the index must not change a single choice, ties included.
std::vector<Path> scan_order(const std::vector<Path>& paths, Point& head) {
  const size_t n = paths.size();
  const auto containers = containing_paths(paths);
  std::vector<size_t> blockers(n, 0);
  for (const auto& list : containers)
    for (size_t c : list) ++blockers[c];
  std::vector<bool> done(n, false);
  std::vector<Path> out;
  for (size_t step = 0; step < n; ++step) {
    size_t best = n, vertex = 0;
    bool reversed = false;
    double best_d = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < n; ++i) {
      if (done[i] || blockers[i] > 0) continue;
      const auto& pts = paths[i].points;
      if (paths[i].closed) {
        for (size_t v = 0; v < pts.size(); ++v)
          if (double d = distance(head, pts[v]); d < best_d) best = i, vertex = v, reversed = false, best_d = d;
      } else {
        if (double d = distance(head, pts.front()); d < best_d) best = i, vertex = 0, reversed = false, best_d = d;
        if (double d = distance(head, pts.back()); d < best_d) best = i, vertex = pts.size() - 1, reversed = true, best_d = d;
      }
    }
    done[best] = true;
    for (size_t c : containers[best]) --blockers[c];
    Path p = paths[best];
    if (p.closed) std::rotate(p.points.begin(), p.points.begin() + static_cast<long>(vertex), p.points.end());
    else if (reversed) std::reverse(p.points.begin(), p.points.end());
    head = p.closed ? p.points.front() : p.points.back();
    out.push_back(std::move(p));
  }
  return out;
}

// Containment as the pairwise test defines it (nesting.h), for every pair.
std::vector<std::vector<size_t>> pairwise_containers(const std::vector<Path>& paths) {
  std::vector<std::vector<size_t>> result(paths.size());
  for (size_t b = 0; b < paths.size(); ++b) {
    if (!paths[b].closed || paths[b].points.size() < 3) continue;
    const double area_b = std::fabs(signed_area(paths[b].points));
    if (area_b <= 0) continue;
    for (size_t a = 0; a < paths.size(); ++a) {
      if (a == b || !bounds_of(paths[b]).contains(bounds_of(paths[a]))) continue;
      if (paths[a].closed && std::fabs(signed_area(paths[a].points)) >= area_b) continue;
      size_t inside = 0, tested = 0;
      const auto& pts = paths[a].points;
      for (size_t i = 0; i < pts.size(); i += std::max<size_t>(1, pts.size() / 9), ++tested)
        inside += point_in_polygon(pts[i], paths[b].points);
      if (2 * inside > tested) result[a].push_back(b);
    }
  }
  return result;
}

// Grids of equal squares (many equal distances), squares nested in squares, duplicates,
// open lines and single points, in a shuffled order.
std::vector<Path> scene(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coord(0, 200);
  std::vector<Path> paths;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) paths.push_back(square(10.0 * i, 10.0 * j, 5));
  for (int k = 0; k < 8; ++k) {
    const double x = coord(rng), y = coord(rng);
    paths.push_back(square(x, y, 40));
    paths.push_back(square(x + 5, y + 5, 20));
    paths.push_back(square(x + 10, y + 10, 5));
    paths.push_back(Path{{{x + 1, y + 1}, {x + 3, y + 30}}, false});
  }
  paths.push_back(square(100, 100, 5));
  paths.push_back(square(100, 100, 5));  // a duplicate
  paths.push_back(Path{{{coord(rng), coord(rng)}}, false});
  std::shuffle(paths.begin(), paths.end(), rng);
  return paths;
}

TEST(LaserOrder, TheSpatialIndexChoosesExactlyAsAScanOfEveryPath) {
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const std::vector<Path> paths = scene(seed);
    EXPECT_EQ(containing_paths(paths), pairwise_containers(paths)) << "seed " << seed;
    Point head_a{0, 0}, head_b{0, 0};
    const auto indexed = order_paths(paths, head_a);
    const auto scanned = scan_order(paths, head_b);
    ASSERT_EQ(indexed.size(), scanned.size());
    for (size_t i = 0; i < indexed.size(); ++i) {
      ASSERT_EQ(indexed[i].closed, scanned[i].closed) << "seed " << seed << " path " << i;
      ASSERT_EQ(indexed[i].points.size(), scanned[i].points.size()) << "seed " << seed << " path " << i;
      for (size_t k = 0; k < indexed[i].points.size(); ++k) {
        EXPECT_EQ(indexed[i].points[k].x, scanned[i].points[k].x) << "seed " << seed << " path " << i;
        EXPECT_EQ(indexed[i].points[k].y, scanned[i].points[k].y) << "seed " << seed << " path " << i;
      }
    }
    EXPECT_EQ(head_a.x, head_b.x);
    EXPECT_EQ(head_a.y, head_b.y);
  }
}

}  // namespace
}  // namespace atelier::laser
