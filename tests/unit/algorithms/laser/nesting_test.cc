// Which laser paths contain which (algorithms/laser/nesting.h).
#include <gtest/gtest.h>

#include "algorithms/laser/nesting.h"
#include "tests/support/laser_test_shapes.h"

namespace atelier::laser {
namespace {

using testing::square;

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

}  // namespace
}  // namespace atelier::laser
