// Parquetry features (eq. 1-2) and the patch queue (paper 3.3).
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <set>

#include "algorithms/parquetry/features.h"
#include "algorithms/parquetry/order.h"

namespace atelier::parquetry {
namespace {

TEST(ParquetryFeatures, HistogramMatchingMovesTheTargetIntoTheWoodsGamut) {
  std::array<double, 256> target{}, wood{};
  for (int v = 0; v < 256; ++v) target[v] = 1;   // a photo using every grey level
  for (int v = 50; v <= 100; ++v) wood[v] = 1;   // wood only between 50 and 100
  const auto none = matching_lut(target, wood, 0.0);
  const auto full = matching_lut(target, wood, 1.0);
  const auto half = matching_lut(target, wood, 0.5);
  for (int v = 0; v < 256; ++v) {
    EXPECT_FLOAT_EQ(none[v] * 255, v);
    EXPECT_GE(full[v] * 255, 50 - 1e-3);
    EXPECT_LE(full[v] * 255, 100 + 1e-3);
    EXPECT_NEAR(half[v], (none[v] + full[v]) / 2, 1e-6);
    if (v > 0) {
      EXPECT_GE(full[v], full[v - 1]);
    }
  }
  EXPECT_NEAR(full[0] * 255, 50, 1e-3);
  EXPECT_NEAR(full[255] * 255, 100, 1e-3);
  EXPECT_NEAR(full[128] * 255, 75, 1.0);  // the median goes to the wood's median
}

TEST(ParquetryFeatures, EdgeFeatureReadsOneOnABlackToWhiteStep) {
  cv::Mat step = cv::Mat::zeros(20, 20, CV_8UC1);
  step.colRange(10, 20).setTo(255);
  const cv::Mat e = edge(intensity(step));
  double hi = 0;
  cv::minMaxLoc(e, nullptr, &hi);
  EXPECT_NEAR(hi, 1.0, 1e-5);
  EXPECT_FLOAT_EQ(e.at<float>(10, 2), 0.0f);
}

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
