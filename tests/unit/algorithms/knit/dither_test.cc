// Dithering a grey stitch grid to the starting 0/1 pattern (algorithms/knit/dither.h):
// threshold, error diffusion and ordered dithering, and the automatic choice.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "algorithms/knit/dither.h"
#include "algorithms/knit/stitch_grid.h"
#include "tests/support/knit_test_images.h"

namespace atelier::knit {
namespace {

const Dither kMethods[] = {Dither::threshold, Dither::floyd_steinberg, Dither::atkinson,
                           Dither::ordered};

// 64 rows of a left-to-right ramp from black (0) to white (255), one grey level per column.
cv::Mat gradient() {
  cv::Mat g(64, 256, CV_8UC1);
  for (int y = 0; y < g.rows; ++y)
    for (int x = 0; x < g.cols; ++x) g.at<uint8_t>(y, x) = static_cast<uint8_t>(x);
  return g;
}

double dark_share(const cv::Mat& grid) { return cv::mean(grid)[0]; }
double expected_dark(const cv::Mat& gray) { return 1.0 - cv::mean(gray)[0] / 255.0; }

cv::Mat gray_of(const char* name, int width) {
  return to_stitch_grid(testing::load_test_image(name), GaugeParams{width, 28, 36});
}

TEST(KnitDither, OutputIsZeroOneGridOfTheSameSize) {
  const cv::Mat gray = gray_of("butterfly.jpg", 140);
  for (Dither d : kMethods) {
    const cv::Mat grid = dither(gray, d);
    EXPECT_EQ(grid.type(), CV_8UC1);
    EXPECT_EQ(grid.size(), gray.size());
    double max_value = 0;
    cv::minMaxLoc(grid, nullptr, &max_value);
    EXPECT_EQ(max_value, 1.0) << dither_name(d);
  }
}

TEST(KnitDither, ThresholdMarksDarkPixelsAsContrast) {
  const cv::Mat grid = dither(gradient(), Dither::threshold, 100);
  for (int x = 0; x < 256; ++x) EXPECT_EQ(grid.at<uint8_t>(10, x), x < 100 ? 1 : 0) << x;
}

TEST(KnitDither, DarkStitchesFollowTheGreyLevelOfAGradient) {
  const cv::Mat gray = gradient();
  for (Dither d : {Dither::floyd_steinberg, Dither::atkinson, Dither::ordered}) {
    const cv::Mat grid = dither(gray, d);
    // Bands of 32 grey levels: the share of dark stitches tracks 1 - grey/255.
    for (int band = 0; band < 8; ++band) {
      const cv::Rect r(band * 32, 0, 32, gray.rows);
      const double tolerance = d == Dither::atkinson ? 0.12 : 0.05;  // Atkinson loses 1/4 of the error
      EXPECT_NEAR(dark_share(grid(r)), expected_dark(gray(r)), tolerance)
          << dither_name(d) << " band " << band;
    }
    // Darker bands never get fewer dark stitches than lighter ones.
    for (int band = 1; band < 8; ++band)
      EXPECT_LE(dark_share(grid(cv::Rect(band * 32, 0, 32, 64))),
                dark_share(grid(cv::Rect((band - 1) * 32, 0, 32, 64))))
          << dither_name(d);
  }
}

TEST(KnitDither, FloydSteinbergKeepsTheMeanOfRealImages) {
  for (const char* name : {"starry_night.jpg", "fruits.jpg", "butterfly.jpg"}) {
    const cv::Mat gray = gray_of(name, 200);
    EXPECT_NEAR(dark_share(dither(gray, Dither::floyd_steinberg)), expected_dark(gray), 0.03) << name;
    EXPECT_NEAR(dark_share(dither(gray, Dither::ordered)), expected_dark(gray), 0.06) << name;
    EXPECT_NEAR(dark_share(dither(gray, Dither::atkinson)), expected_dark(gray), 0.12) << name;
  }
}

TEST(KnitDither, DitheredImageLooksLikeItsSourceFromADistance) {
  // Block averages of dark stitches follow block darkness of the source.
  const cv::Mat gray = gray_of("fruits.jpg", 256);
  cv::Mat want;
  gray.convertTo(want, CV_32F, -1.0 / 255.0, 1.0);
  cv::resize(want, want, cv::Size(gray.cols / 8, gray.rows / 8), 0, 0, cv::INTER_AREA);
  for (Dither d : {Dither::floyd_steinberg, Dither::atkinson, Dither::ordered}) {
    cv::Mat got;
    dither(gray, d).convertTo(got, CV_32F);
    cv::resize(got, got, want.size(), 0, 0, cv::INTER_AREA);
    EXPECT_LT(cv::mean(cv::abs(got - want))[0], 0.12) << dither_name(d);
  }
}

TEST(KnitDither, AutoTellsLineDrawingsFromContinuousTone) {
  for (const char* name : {"pic1.png", "pic3.png", "pic5.png", "LinuxLogo.jpg"}) {
    const cv::Mat full = to_gray(testing::load_test_image(name));
    EXPECT_TRUE(looks_like_line_drawing(full)) << name;
    EXPECT_TRUE(looks_like_line_drawing(gray_of(name, 120))) << name << " at 120 stitches";
    EXPECT_EQ(resolve_dither(Dither::automatic, full), Dither::threshold) << name;
  }
  for (const char* name : {"butterfly.jpg", "fruits.jpg", "starry_night.jpg"}) {
    const cv::Mat full = to_gray(testing::load_test_image(name));
    EXPECT_FALSE(looks_like_line_drawing(full)) << name;
    EXPECT_FALSE(looks_like_line_drawing(gray_of(name, 120))) << name << " at 120 stitches";
    EXPECT_EQ(resolve_dither(Dither::automatic, full), Dither::floyd_steinberg) << name;
  }
  EXPECT_EQ(resolve_dither(Dither::ordered, gradient()), Dither::ordered);
}

TEST(KnitDither, NamesAndErrors) {
  for (Dither d : {Dither::threshold, Dither::floyd_steinberg, Dither::atkinson, Dither::ordered,
                   Dither::automatic})
    EXPECT_EQ(dither_from_name(dither_name(d)), d);
  EXPECT_THROW(dither_from_name("halftone"), std::invalid_argument);
  EXPECT_THROW(dither(gradient(), Dither::automatic), std::invalid_argument);
  EXPECT_THROW(dither(gradient(), Dither::threshold, 300), std::invalid_argument);
  EXPECT_THROW(dither(cv::Mat(), Dither::threshold), std::invalid_argument);
  EXPECT_THROW(dither(cv::Mat(4, 4, CV_8UC3), Dither::threshold), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::knit
