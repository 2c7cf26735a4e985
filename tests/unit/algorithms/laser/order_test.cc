// The cutting order of laser paths (algorithms/laser/order.h): inner before outer, open paths
// reversed when nearer.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace atelier::laser
