// preview.png written from the grid's structure (convert/knit/knit_preview_png.h): a valid PNG
// that any decoder reads as exactly render_preview's image, for every stitch size.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "algorithms/knit/preview.h"
#include "convert/knit/knit_preview_png.h"
#include "tests/unit/algorithms/knit/random_grid_fixture.h"

namespace atelier {
namespace {

cv::Mat decode(const std::string& png) {
  return cv::imdecode(std::vector<uchar>(png.begin(), png.end()), cv::IMREAD_UNCHANGED);
}

TEST(KnitPreviewPng, DecodesToTheRenderedPreviewPixelForPixel) {
  // Long runs (a solid block: repeats longer than one match) and random stitches.
  cv::Mat grid = knit::testing::random_grid(cv::Size(150, 40), 7);
  grid(cv::Rect(0, 0, 140, 10)).setTo(1);
  grid(cv::Rect(5, 20, 145, 3)).setTo(0);
  for (int px : {1, 2, 3, 5, 10, 12}) {
    for (double aspect : {0.78, 1.0, 1.4}) {
      knit::PreviewStyle style;
      style.stitch_px = px;
      style.stitch_aspect = aspect;
      const std::string png = encode_preview_png(grid, style);
      ASSERT_FALSE(png.empty()) << px;
      EXPECT_EQ(png.rfind("\x89PNG\r\n\x1a\n", 0), 0u);
      const cv::Mat decoded = decode(png);
      ASSERT_FALSE(decoded.empty()) << "px " << px << " aspect " << aspect << ": not a PNG OpenCV reads";
      const cv::Mat rendered = knit::render_preview(grid, style);
      ASSERT_EQ(decoded.size(), rendered.size()) << px;
      cv::Mat bgr = decoded;
      if (decoded.channels() == 4) cv::cvtColor(decoded, bgr, cv::COLOR_BGRA2BGR);
      ASSERT_EQ(bgr.type(), CV_8UC3);
      EXPECT_EQ(cv::norm(bgr, rendered, cv::NORM_INF), 0) << "px " << px << " aspect " << aspect;
    }
  }
}

// A wide grid whose same-colour tile rows lie more than deflate's 32 KB window apart (a long
// row of one colour, then the other), and a grid of one colour only.
TEST(KnitPreviewPng, FarApartRunsAndOneColourGrids) {
  cv::Mat grid(6, 1000, CV_8UC1, cv::Scalar(0));
  grid(cv::Rect(0, 0, 1, 6)).setTo(1);
  grid(cv::Rect(999, 0, 1, 6)).setTo(1);
  knit::PreviewStyle style;
  style.stitch_px = 12;
  for (const cv::Mat& g : {grid, cv::Mat(5, 7, CV_8UC1, cv::Scalar(1)), cv::Mat(5, 7, CV_8UC1, cv::Scalar(0))}) {
    const cv::Mat decoded = decode(encode_preview_png(g, style));
    ASSERT_FALSE(decoded.empty());
    cv::Mat bgr = decoded;
    if (decoded.channels() == 4) cv::cvtColor(decoded, bgr, cv::COLOR_BGRA2BGR);
    EXPECT_EQ(cv::norm(bgr, knit::render_preview(g, style), cv::NORM_INF), 0) << g.size();
  }
}

// Large stitches have more than 256 colours in their two tiles: no palette PNG (the caller
// encodes the render instead).
TEST(KnitPreviewPng, TooManyColoursGivesNothing) {
  knit::PreviewStyle style;
  style.stitch_px = 64;
  style.stitch_aspect = 2.0;
  EXPECT_TRUE(encode_preview_png(knit::testing::random_grid(cv::Size(4, 4), 1), style).empty());
}

}  // namespace
}  // namespace atelier
