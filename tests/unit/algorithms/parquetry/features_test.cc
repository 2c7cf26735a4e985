// Parquetry features (algorithms/parquetry/features.h, eq. 1-2): histogram matching and the
// edge feature.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "algorithms/parquetry/features.h"

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

}  // namespace
}  // namespace atelier::parquetry
