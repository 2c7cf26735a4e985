// The blurred SSIM (algorithms/parquetry/quality.h): the figure a parquetry result is judged by.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "algorithms/parquetry/quality.h"

namespace atelier {
namespace {

// A target with regions and edges: a grey ramp with a dark disc and a light bar.
cv::Mat scene(int w, int h) {
  cv::Mat m(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) m.at<cv::Vec3b>(y, x) = cv::Vec3b::all(60 + 120 * x / w);
  }
  cv::circle(m, {w / 3, h / 2}, h / 4, cv::Scalar::all(20), cv::FILLED);
  cv::rectangle(m, cv::Rect(2 * w / 3, h / 5, w / 6, 3 * h / 5), cv::Scalar::all(230), cv::FILLED);
  return m;
}

TEST(ParquetryQualityTest, AnImageMatchesItselfExactly) {
  const cv::Mat t = scene(120, 80);
  EXPECT_NEAR(parquetry::blurred_ssim(t, t, 2.0), 1.0, 1e-6);
}

// Grain finer than the 2 mm blur hardly counts: the scene with a 1-px checkerboard of +-25 grey
// levels (wood grain) still scores high, while the scene mirrored (the shapes in the wrong
// places, same grey levels) scores far lower.
TEST(ParquetryQualityTest, FineGrainCountsLittleWrongShapesCountMuch) {
  const cv::Mat t = scene(160, 100);
  cv::Mat grain = t.clone();
  for (int y = 0; y < grain.rows; ++y) {
    for (int x = 0; x < grain.cols; ++x) {
      cv::Vec3b& p = grain.at<cv::Vec3b>(y, x);
      const int d = (x + y) % 2 ? 25 : -25;
      for (int c = 0; c < 3; ++c) p[c] = cv::saturate_cast<uchar>(p[c] + d);
    }
  }
  cv::Mat mirrored;
  cv::flip(t, mirrored, 1);
  const double s_grain = parquetry::blurred_ssim(grain, t, 2.0);
  const double s_mirror = parquetry::blurred_ssim(mirrored, t, 2.0);
  EXPECT_GT(s_grain, 0.97);
  EXPECT_LT(s_mirror, 0.8);
  // At 0.25 px/mm the same checkerboard is 4 mm grain: no longer blurred away as much.
  EXPECT_LT(parquetry::blurred_ssim(grain, t, 0.25), s_grain);
}

TEST(ParquetryQualityTest, RefusesImagesOfDifferentSizes) {
  EXPECT_THROW(parquetry::blurred_ssim(scene(100, 80), scene(100, 81), 1.0), std::invalid_argument);
  EXPECT_THROW(parquetry::blurred_ssim(cv::Mat(), cv::Mat(), 1.0), std::invalid_argument);
}

}  // namespace
}  // namespace atelier
