// The stitch-shaped preview of a pattern (algorithms/knit/preview.h): size, aspect and the
// shaded V of each stitch.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <stdexcept>

#include "algorithms/knit/preview.h"
#include "tests/unit/algorithms/knit/random_grid_fixture.h"

namespace atelier::knit {
namespace {

using testing::random_grid;

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
