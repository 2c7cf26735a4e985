// Image to stitch grid (algorithms/knit/stitch_grid.h): gauge, orientation, shrinking and
// alpha.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "algorithms/knit/stitch_grid.h"
#include "tests/support/knit_test_images.h"

namespace atelier::knit {
namespace {

TEST(KnitStitchGrid, GaugeKeepsTheKnittedAspect) {
  const cv::Mat square(300, 300, CV_8UC3, cv::Scalar(200, 100, 50));
  const cv::Mat grid = to_stitch_grid(square, GaugeParams{100, 28, 36});
  EXPECT_EQ(grid.type(), CV_8UC1);
  EXPECT_EQ(grid.cols, 100);
  EXPECT_EQ(grid.rows, std::lround(100 * 36.0 / 28.0));  // 129: stitches are wider than tall
  const cv::Mat even = to_stitch_grid(square, GaugeParams{100, 30, 30});
  EXPECT_EQ(even.rows, 100);
}

TEST(KnitStitchGrid, RealImageSize) {
  const cv::Mat image = testing::load_test_image("starry_night.jpg");  // 752x600
  const cv::Mat grid = to_stitch_grid(image, GaugeParams{120, 28, 36});
  EXPECT_EQ(grid.cols, 120);
  EXPECT_EQ(grid.rows, std::lround(120 * 600.0 / 752.0 * 36.0 / 28.0));
}

TEST(KnitStitchGrid, HorizontalKeepsTopLeftVerticalRotatesClockwise) {
  // 300 wide, 100 high, the left third black.
  cv::Mat picture(100, 300, CV_8UC1, cv::Scalar(255));
  picture(cv::Rect(0, 0, 100, 100)).setTo(0);
  const cv::Mat h = to_stitch_grid(picture, GaugeParams{60, 28, 36});
  EXPECT_EQ(h.size(), cv::Size(60, std::lround(60 * 100.0 / 300.0 * 36 / 28)));
  EXPECT_LT(h.at<uint8_t>(h.rows / 2, 2), 20);
  EXPECT_GT(h.at<uint8_t>(h.rows / 2, 57), 235);

  GaugeParams vertical{60, 28, 36, Orientation::vertical};
  const cv::Mat v = to_stitch_grid(picture, vertical);
  EXPECT_EQ(v.size(), cv::Size(60, std::lround(60 * 300.0 / 100.0 * 36 / 28)));  // axes swapped
  // Clockwise: the picture's left edge becomes the top of the fabric.
  EXPECT_LT(v.at<uint8_t>(2, v.cols / 2), 20);
  EXPECT_GT(v.at<uint8_t>(v.rows - 3, v.cols / 2), 235);
}

TEST(KnitStitchGrid, ShrinkingAveragesFineDetail) {
  // A one-pixel checkerboard shrunk 4x reads as mid grey (area averaging), not as
  // black or white aliasing.
  cv::Mat checker(200, 200, CV_8UC1);
  for (int y = 0; y < 200; ++y)
    for (int x = 0; x < 200; ++x) checker.at<uint8_t>(y, x) = (x + y) % 2 ? 255 : 0;
  const cv::Mat grid = to_stitch_grid(checker, GaugeParams{50, 30, 30});
  double lo = 0, hi = 0;
  cv::minMaxLoc(grid, &lo, &hi);
  EXPECT_GE(lo, 120);
  EXPECT_LE(hi, 135);
}

TEST(KnitStitchGrid, AlphaIsCompositedOnWhite) {
  cv::Mat rgba(40, 40, CV_8UC4, cv::Scalar(0, 0, 0, 0));  // transparent black
  rgba(cv::Rect(0, 0, 20, 40)).setTo(cv::Scalar(0, 0, 0, 255));  // opaque black left half
  rgba(cv::Rect(20, 0, 10, 40)).setTo(cv::Scalar(0, 0, 0, 128));  // half-transparent black
  const cv::Mat gray = to_gray(rgba);
  EXPECT_EQ(gray.at<uint8_t>(5, 5), 0);
  EXPECT_NEAR(gray.at<uint8_t>(5, 25), 127, 1);
  EXPECT_EQ(gray.at<uint8_t>(5, 35), 255);
  // The real logo with alpha: its transparent background becomes white.
  const cv::Mat logo = to_stitch_grid(testing::load_test_image("opencv-logo.png"),
                                      GaugeParams{60, 28, 36});
  EXPECT_EQ(logo.at<uint8_t>(0, 0), 255);
}

TEST(KnitStitchGrid, RejectsBadParameters) {
  const cv::Mat image(50, 50, CV_8UC3, cv::Scalar::all(128));
  EXPECT_THROW(to_stitch_grid(image, GaugeParams{0, 28, 36}), std::invalid_argument);
  EXPECT_THROW(to_stitch_grid(image, GaugeParams{100, 0, 36}), std::invalid_argument);
  EXPECT_THROW(to_stitch_grid(image, GaugeParams{100, 28, -1}), std::invalid_argument);
  EXPECT_THROW(to_stitch_grid(image, GaugeParams{100, std::numeric_limits<double>::quiet_NaN(), 36}),
               std::invalid_argument);
  EXPECT_THROW(to_stitch_grid(cv::Mat(), GaugeParams{}), std::invalid_argument);
  EXPECT_THROW(to_stitch_grid(cv::Mat(5, 5, CV_8UC2), GaugeParams{}), std::invalid_argument);
  EXPECT_THROW(to_stitch_grid(cv::Mat(5, 5, CV_16UC1), GaugeParams{}), std::invalid_argument);
  try {
    to_stitch_grid(image, GaugeParams{-3, 28, 36});
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("width"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace atelier::knit
