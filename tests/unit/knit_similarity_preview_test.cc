#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <stdexcept>

#include "algorithms/knit/dither.h"
#include "algorithms/knit/preview.h"
#include "algorithms/knit/similarity.h"
#include "algorithms/knit/stitch_grid.h"
#include "tests/support/knit_test_images.h"

namespace atelier::knit {
namespace {

cv::Mat random_grid(cv::Size size, uint64_t seed) {
  cv::Mat g(size, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(g, cv::RNG::UNIFORM, 0, 2);
  return g;
}

TEST(KnitSimilarity, IdenticalIsOneNoiseIsLow) {
  const cv::Mat grid = random_grid(cv::Size(80, 60), 1);
  cv::Mat source = (grid == 0);  // 255 where background: the grid as a picture
  EXPECT_NEAR(blurred_ssim(source, grid), 1.0, 1e-6);
  EXPECT_NEAR(blurred_ssim(source, grid, 0.0), 1.0, 1e-6);
  const cv::Mat other = random_grid(grid.size(), 2);
  EXPECT_LT(blurred_ssim(source, other, 0.0), 0.2);
  EXPECT_LT(blurred_ssim(source, other), 0.6);
}

TEST(KnitSimilarity, DitheringResemblesTheSourceMoreThanNoise) {
  const cv::Mat gray = to_stitch_grid(testing::load_test_image("fruits.jpg"), GaugeParams{160, 28, 36});
  const double fs = blurred_ssim(gray, dither(gray, Dither::floyd_steinberg));
  const double noise = blurred_ssim(gray, random_grid(gray.size(), 3));
  EXPECT_GT(fs, 0.5);
  EXPECT_GT(fs, noise + 0.3);
  EXPECT_LE(fs, 1.0);
  EXPECT_THROW(blurred_ssim(gray, cv::Mat(3, 3, CV_8UC1)), std::invalid_argument);
}

TEST(KnitPreview, SizeFollowsStitchSizeAndAspect) {
  const cv::Mat grid = random_grid(cv::Size(30, 20), 4);
  PreviewStyle style;
  style.stitch_px = 12;
  style.stitch_aspect = 0.78;
  const cv::Mat img = render_preview(grid, style);
  EXPECT_EQ(img.type(), CV_8UC3);
  EXPECT_EQ(img.cols, 30 * 12);
  EXPECT_EQ(img.rows, 20 * 9);  // round(12 * 0.78) = 9
  style.stitch_px = 7;
  style.stitch_aspect = 1.0;
  EXPECT_EQ(render_preview(grid, style).size(), cv::Size(30 * 7, 20 * 7));
  style.stitch_px = 0;
  EXPECT_THROW(render_preview(grid, style), std::invalid_argument);
}

TEST(KnitPreview, StitchesShowTheirYarnAsAShadedV) {
  cv::Mat grid(4, 6, CV_8UC1, cv::Scalar(0));
  grid(cv::Rect(3, 0, 3, 4)).setTo(1);
  PreviewStyle style;
  style.stitch_px = 16;
  style.stitch_aspect = 1.0;
  const cv::Mat img = render_preview(grid, style);
  const cv::Mat bg = img(cv::Rect(16, 16, 16, 16)), fg = img(cv::Rect(64, 16, 16, 16));
  // Each stitch is its yarn's colour on average, a little darker for the gaps and shading.
  const cv::Scalar bg_mean = cv::mean(bg), fg_mean = cv::mean(fg);
  for (int c = 0; c < 3; ++c) {
    EXPECT_LT(bg_mean[c], style.background[c]);
    EXPECT_GT(bg_mean[c], style.background[c] * 0.6);
    EXPECT_GT(fg_mean[c], style.contrast[c] * 0.6);
    EXPECT_LT(fg_mean[c], style.contrast[c] + 10);
  }
  // Shaded, not flat: the legs are lighter than the gap at the top centre between them.
  cv::Mat grey;
  cv::extractChannel(bg, grey, 1);
  const int gap = grey.at<uint8_t>(1, 8), leg = grey.at<uint8_t>(8, 4);
  EXPECT_GT(leg, gap + 20);
  // V shape: left-right mirror symmetric.
  cv::Mat mirrored;
  cv::flip(bg, mirrored, 1);
  EXPECT_LT(cv::norm(bg, mirrored, cv::NORM_INF), 40);
}

}  // namespace
}  // namespace atelier::knit
