// Similarity of a pattern to its source seen from a distance (algorithms/knit/similarity.h).
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "algorithms/knit/dither.h"
#include "algorithms/knit/similarity.h"
#include "algorithms/knit/stitch_grid.h"
#include "tests/support/knit_test_images.h"
#include "tests/unit/algorithms/knit/random_grid_fixture.h"

namespace atelier::knit {
namespace {

using testing::random_grid;

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

}  // namespace
}  // namespace atelier::knit
