// The colours of paper section 4 (algorithms/embroidery/colors.h, through segment()): palette
// size and accuracy, the white sheet and transparent pixels not sewn.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>

#include "algorithms/embroidery/segment.h"
#include "tests/unit/algorithms/embroidery/segment_fixture.h"

namespace atelier::embroidery {
namespace {

using test::load;
using test::segment_drawing;

cv::Vec3f lab_of(cv::Vec3b bgr) {
  cv::Mat3f one(1, 1, cv::Vec3f(bgr[0] / 255.f, bgr[1] / 255.f, bgr[2] / 255.f)), lab;
  cv::cvtColor(one, lab, cv::COLOR_BGR2Lab);
  return lab.at<cv::Vec3f>(0, 0);
}

TEST(EmbroideryColors, FourFlatColoursWithNoiseGiveFourPaletteColours) {
  const cv::Vec3b truth[4] = {{40, 40, 200}, {200, 60, 30}, {50, 170, 60}, {30, 200, 230}};
  cv::Mat3b img(200, 200);
  for (int q = 0; q < 4; ++q) img(cv::Rect((q % 2) * 100, (q / 2) * 100, 100, 100)).setTo(truth[q]);
  cv::Mat noise(img.size(), CV_16SC3);
  cv::randn(noise, 0, 8);
  cv::Mat sum;
  img.convertTo(sum, CV_16SC3);
  cv::add(sum, noise, sum);
  sum.convertTo(img, CV_8UC3);
  const Segmentation s = segment(img, ColorParams{}, LabelParams{});
  ASSERT_EQ(s.palette.bgr.size(), 4u);
  for (const cv::Vec3b& t : truth) {
    double nearest = 1e9;
    for (const cv::Vec3f& p : s.palette.lab) nearest = std::min(nearest, cv::norm(p - lab_of(t)));
    EXPECT_LT(nearest, 3.0) << "no palette colour near " << cv::Mat(t).t();
  }
  EXPECT_EQ(s.components, 4);
}

TEST(EmbroideryColors, AskedNumberOfColoursIsWhatYouGet) {
  const cv::Mat img = load("fruits.jpg");
  for (int n : {3, 7}) {
    ColorParams cp;
    cp.colors = n;
    cp.background = Background::sew;
    const Segmentation s = segment(img, cp, LabelParams{});
    EXPECT_EQ(s.palette.bgr.size(), static_cast<size_t>(n));
    EXPECT_EQ(s.palette.lab.size(), static_cast<size_t>(n));
  }
}

TEST(EmbroideryColors, WhiteSheetOfADrawingIsNotSewnUnlessAsked) {
  cv::Mat1b shape(200, 200, uchar(0));
  cv::circle(shape, {100, 100}, 50, 255, cv::FILLED);
  const Segmentation s = segment_drawing(shape);
  ASSERT_EQ(s.palette.bgr.size(), 1u) << "only the ink is a thread";
  EXPECT_LT(s.palette.lab[0][0], 20) << "the thread is the black ink";
  EXPECT_EQ(s.color_index(5, 5), -1);
  EXPECT_EQ(s.region_id(5, 5), -1);
  // All of the disk is sewn (the median filter may round a few boundary pixels).
  EXPECT_NEAR(cv::countNonZero(s.color_index >= 0), cv::countNonZero(shape), 0.01 * cv::countNonZero(shape));
  EXPECT_EQ(s.color_index(100, 100), 0);

  cv::Mat3b img(shape.size(), cv::Vec3b(255, 255, 255));
  img.setTo(cv::Vec3b(0, 0, 0), shape);
  ColorParams sew;
  sew.background = Background::sew;
  const Segmentation all = segment(img, sew, LabelParams{});
  EXPECT_EQ(all.palette.bgr.size(), 2u);
  EXPECT_EQ(cv::countNonZero(all.color_index >= 0), img.rows * img.cols);
}

TEST(EmbroideryColors, TransparentPixelsOfTheLogoAreNotSewn) {
  const cv::Mat img = load("opencv-logo.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(img.type(), CV_8UC4);
  ColorParams sew;
  sew.background = Background::sew;  // even when asked to sew everything
  const Segmentation s = segment(img, sew, LabelParams{});
  int transparent = 0, opaque_sewn = 0, opaque = 0;
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      if (img.at<cv::Vec4b>(y, x)[3] < 128) {
        ++transparent;
        ASSERT_EQ(s.color_index(y, x), -1) << x << "," << y;
        ASSERT_EQ(s.region_id(y, x), -1) << x << "," << y;
      } else {
        ++opaque;
        opaque_sewn += s.region_id(y, x) >= 0;
      }
    }
  EXPECT_GT(transparent, 0);
  EXPECT_GT(opaque_sewn, opaque * 95 / 100) << "the logo itself is sewn";
  EXPECT_GE(s.palette.bgr.size(), 3u) << "red, green and blue rings";
}

}  // namespace
}  // namespace atelier::embroidery
