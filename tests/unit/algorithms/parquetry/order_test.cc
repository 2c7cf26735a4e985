// The patch queue (algorithms/parquetry/order.h, paper 3.3): saliency and centre order.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <set>

#include "algorithms/parquetry/order.h"

namespace atelier::parquetry {
namespace {

TEST(ParquetryOrder, SaliencyPutsTheDetailedCellFirst) {
  // Flat grey with one busy cell (a checkerboard) at column 3, row 1 of a 5 x 4 grid.
  cv::Mat image(4 * 20, 5 * 20, CV_8UC3, cv::Scalar(128, 128, 128));
  for (int y = 0; y < 20; ++y) {
    for (int x = 0; x < 20; ++x) {
      const uchar v = ((x / 4) + (y / 4)) % 2 ? 255 : 0;
      image.at<cv::Vec3b>(20 + y, 60 + x) = {v, v, v};
    }
  }
  const auto order = patch_order(image, 5, 4, 20, Order::saliency, 1);
  ASSERT_EQ(order.size(), 20u);
  EXPECT_EQ(order[0], 1 * 5 + 3);
}

TEST(ParquetryOrder, CentreOrderGoesOutwardsAndSeedOnlyBreaksTies) {
  const cv::Mat image(6 * 10, 6 * 10, CV_8UC3, cv::Scalar::all(0));
  const auto a = patch_order(image, 6, 6, 10, Order::center, 1);
  const auto b = patch_order(image, 6, 6, 10, Order::center, 2);
  const std::set<int> middle = {2 * 6 + 2, 2 * 6 + 3, 3 * 6 + 2, 3 * 6 + 3};
  for (int i = 0; i < 4; ++i) {
    EXPECT_TRUE(middle.count(a[i])) << a[i];
    EXPECT_TRUE(middle.count(b[i])) << b[i];
  }
  EXPECT_NE(a, b);  // the four middle cells tie; the seed orders them
  EXPECT_EQ(a, patch_order(image, 6, 6, 10, Order::center, 1));
}

}  // namespace
}  // namespace atelier::parquetry
