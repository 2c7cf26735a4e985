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


// ---- issue 21, points 3 and 4: opaque RGBA like RGB; distinct colours get distinct threads ----

// 8-bit B,G,R from R,G,B (the issue gives its colours as RGB).
cv::Vec3b rgb(int r, int g, int b) { return cv::Vec3b(uchar(b), uchar(g), uchar(r)); }

// Adds Gaussian noise of sigma (per 8-bit channel), fixed seed.
cv::Mat3b noisy(const cv::Mat3b& img, double sigma, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat noise(img.size(), CV_16SC3), sum;
  rng.fill(noise, cv::RNG::NORMAL, 0, sigma);
  img.convertTo(sum, CV_16SC3);
  cv::add(sum, noise, sum);
  cv::Mat3b out;
  sum.convertTo(out, CV_8UC3);
  return out;
}

double nearest_de(const Palette& p, cv::Vec3b bgr, int* which = nullptr) {
  double best = 1e9;
  for (size_t k = 0; k < p.lab.size(); ++k) {
    const double d = cv::norm(p.lab[k] - lab_of(bgr));
    if (d < best) {
      best = d;
      if (which) *which = static_cast<int>(k);
    }
  }
  return best;
}

TEST(EmbroideryColors, TheIssuesFourCloseFlatColoursGetFourThreadsEachNearItsSource) {
  // CIE76 23..55 apart: clearly different threads, though all of middling lightness.
  const cv::Vec3b truth[4] = {rgb(120, 152, 120), rgb(216, 152, 120), rgb(120, 184, 184), rgb(120, 120, 168)};
  for (double sigma : {0.0, 4.0}) {
    cv::Mat3b img(400, 400);
    for (int q = 0; q < 4; ++q) img(cv::Rect((q % 2) * 200, (q / 2) * 200, 200, 200)).setTo(truth[q]);
    if (sigma > 0) img = noisy(img, sigma, 21);
    const Segmentation s = segment(img, ColorParams{}, LabelParams{});
    ASSERT_EQ(s.palette.bgr.size(), 4u) << "sigma " << sigma;
    for (int q = 0; q < 4; ++q) {
      int k = -1;
      EXPECT_LT(nearest_de(s.palette, truth[q], &k), 5.0) << "colour " << q << " sigma " << sigma;
      // The block is sewn in that thread.
      EXPECT_EQ(s.color_index((q / 2) * 200 + 100, (q % 2) * 200 + 100), k) << "colour " << q;
    }
  }
}

TEST(EmbroideryColors, ASmallYellowPatchOnOliveGetsItsOwnThread) {
  // 60 x 60 mm of olive at 10 px/mm with a 3 mm^2 yellow highlight (a disk of radius 1 mm):
  // 0.08 % of the pixels, so a subsample barely sees it, but it is a visible, clearly
  // different area (CIE76 ~40 from the olive).
  const cv::Vec3b olive = rgb(120, 120, 30), yellow = rgb(250, 225, 70);
  cv::Mat3b img(600, 600, olive);
  cv::circle(img, {400, 200}, 10, yellow, cv::FILLED, cv::LINE_8);
  img = noisy(img, 3.0, 7);
  ColorParams cp;
  cp.min_area_px = 100;  // min_region_mm2 = 1 at 10 px/mm
  const Segmentation s = segment(img, cp, LabelParams{});
  ASSERT_EQ(s.palette.bgr.size(), 2u) << "olive and yellow";
  int ky = -1, ko = -1;
  EXPECT_LT(nearest_de(s.palette, yellow, &ky), 5.0);
  EXPECT_LT(nearest_de(s.palette, olive, &ko), 5.0);
  ASSERT_NE(ky, ko);
  EXPECT_EQ(s.color_index(200, 400), ky) << "the highlight is sewn yellow";
  EXPECT_EQ(s.color_index(100, 100), ko);
}

TEST(EmbroideryColors, OrangeCandiesAndRedCandiesGetTwoThreads) {
  // Dots of 4 mm diameter at 10 px/mm on a white sheet: 12 red, 3 orange.
  const cv::Vec3b red = rgb(200, 30, 35), orange = rgb(240, 130, 30);
  cv::Mat3b img(500, 500, cv::Vec3b(255, 255, 255));
  for (int i = 0; i < 15; ++i)
    cv::circle(img, {50 + (i % 5) * 100, 80 + (i / 5) * 150}, 20, i % 5 == 2 ? orange : red, cv::FILLED);
  img = noisy(img, 3.0, 11);
  ColorParams cp;
  cp.min_area_px = 100;
  const Segmentation s = segment(img, cp, LabelParams{});
  ASSERT_EQ(s.palette.bgr.size(), 2u) << "red and orange; the white sheet is not sewn";
  int kr = -1, ko = -1;
  EXPECT_LT(nearest_de(s.palette, red, &kr), 5.0);
  EXPECT_LT(nearest_de(s.palette, orange, &ko), 5.0);
  ASSERT_NE(kr, ko);
  for (int i = 0; i < 15; ++i)
    EXPECT_EQ(s.color_index(80 + (i / 5) * 150, 50 + (i % 5) * 100), i % 5 == 2 ? ko : kr) << "dot " << i;
  EXPECT_EQ(s.color_index(5, 5), -1);
}

TEST(EmbroideryColors, FruitsThreadsAreTheMeanColourOfThePixelsTheySew) {
  // Each thread is the CIELab mean of the (median-filtered) pixels it sews, so against the
  // unfiltered pixels it differs only by what the 3x3 median moves and by the specks under
  // min_area_px that joined the region; CIE76 4 is under 2 JND of thread shades.
  const cv::Mat img = load("fruits.jpg");
  const Segmentation s = segment(img, ColorParams{}, LabelParams{});
  ASSERT_GE(s.palette.bgr.size(), 4u);
  cv::Mat3b bgr = img;
  const cv::Mat3f lab = [&] {
    cv::Mat3f f, l;
    bgr.convertTo(f, CV_32F, 1.0 / 255);
    cv::cvtColor(f, l, cv::COLOR_BGR2Lab);
    return l;
  }();
  for (size_t k = 0; k < s.palette.lab.size(); ++k) {
    const cv::Mat1b mine = s.color_index == static_cast<int>(k);
    ASSERT_GT(cv::countNonZero(mine), 0) << "thread " << k << " sews nothing";
    const cv::Scalar m = cv::mean(lab, mine);
    const double de = cv::norm(s.palette.lab[k] - cv::Vec3f(float(m[0]), float(m[1]), float(m[2])));
    EXPECT_LT(de, 4.0) << "thread " << k;
    // palette.bgr is the palette.lab colour.
    EXPECT_LT(cv::norm(lab_of(s.palette.bgr[k]) - s.palette.lab[k]), 1.0) << "thread " << k;
  }
}

TEST(EmbroideryColors, AnOpaqueRgbaImageIsTreatedLikeTheSameRgbImage) {
  // A black disk and a blue square on a white sheet; as RGBA with alpha 255 everywhere the
  // white is still the fabric.
  cv::Mat3b img(300, 300, cv::Vec3b(255, 255, 255));
  cv::circle(img, {100, 100}, 60, cv::Vec3b(0, 0, 0), cv::FILLED);
  cv::rectangle(img, cv::Rect(170, 170, 100, 100), rgb(30, 60, 200), cv::FILLED);
  cv::Mat4b rgba;
  cv::cvtColor(img, rgba, cv::COLOR_BGR2BGRA);
  const Segmentation a = segment(img, ColorParams{}, LabelParams{});
  const Segmentation b = segment(rgba, ColorParams{}, LabelParams{});
  ASSERT_EQ(a.palette.bgr.size(), 2u);
  ASSERT_EQ(b.palette.bgr.size(), 2u) << "black and blue; the white sheet is not a thread";
  EXPECT_EQ(b.color_index(5, 5), -1) << "the white is not sewn";
  EXPECT_EQ(cv::countNonZero(a.color_index != b.color_index), 0);
  // One transparent pixel makes transparency the background: the white is sewn then.
  rgba(299, 299)[3] = 0;
  const Segmentation c = segment(rgba, ColorParams{}, LabelParams{});
  EXPECT_EQ(c.color_index(299, 299), -1);
  EXPECT_GE(c.color_index(5, 5), 0) << "a partly transparent image keeps its opaque white";
}

}  // namespace
}  // namespace atelier::embroidery
