// The kerf offset (algorithms/laser/kerf.h): outlines grow, holes shrink or vanish, open paths
// stay.
#include <gtest/gtest.h>

#include "algorithms/laser/kerf.h"
#include "tests/support/laser_test_shapes.h"

namespace atelier::laser {
namespace {

using testing::square;
using testing::width_of;

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

}  // namespace
}  // namespace atelier::laser
