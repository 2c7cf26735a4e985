// Paper section 4 end to end (algorithms/embroidery/segment.h): stitch styles of drawn shapes,
// region masks, bad input.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <map>

#include "algorithms/embroidery/segment.h"
#include "tests/unit/algorithms/embroidery/segment_fixture.h"

namespace atelier::embroidery {
namespace {

using test::load;
using test::segment_drawing;

// The style most of the shape's pixels (non-zero in `shape`) were given; counts unsewn too.
std::map<int, int> styles_under(const Segmentation& s, const cv::Mat1b& shape) {
  std::map<int, int> count;  // -1 = not sewn
  for (int y = 0; y < shape.rows; ++y)
    for (int x = 0; x < shape.cols; ++x)
      if (shape(y, x)) {
        const int r = s.region_id(y, x);
        ++count[r < 0 ? -1 : static_cast<int>(s.regions[r].style)];
      }
  return count;
}
Style majority(const std::map<int, int>& count) {
  int best = -1, n = -1;
  for (const auto& [k, v] : count)
    if (v > n) best = k, n = v;
  return Style(best);
}

TEST(EmbroiderySegment, ThinLineBecomesEdgeStitch) {
  for (bool diagonal : {false, true}) {
    cv::Mat1b shape(200, 300, uchar(0));
    if (diagonal) cv::line(shape, {40, 40}, {240, 160}, 255, 2);
    else cv::rectangle(shape, cv::Rect(50, 100, 200, 2), 255, cv::FILLED);
    const Segmentation s = segment_drawing(shape);
    const auto count = styles_under(s, shape);
    EXPECT_EQ(majority(count), Style::edge) << "diagonal " << diagonal;
    EXPECT_LT(count.count(-1) ? count.at(-1) : 0, cv::countNonZero(shape) / 20)
        << "the line is sewn (the median filter may take a pixel at its ends)";
  }
}

TEST(EmbroiderySegment, MediumStripeBecomesSatin) {
  cv::Mat1b shape(200, 300, uchar(0));
  cv::rectangle(shape, cv::Rect(40, 90, 220, 12), 255, cv::FILLED);
  const Segmentation s = segment_drawing(shape);
  EXPECT_EQ(majority(styles_under(s, shape)), Style::satin);
}

TEST(EmbroiderySegment, LargeDiskBecomesLongShort) {
  cv::Mat1b shape(240, 240, uchar(0));
  cv::circle(shape, {120, 120}, 80, 255, cv::FILLED);
  const Segmentation s = segment_drawing(shape);
  const auto count = styles_under(s, shape);
  EXPECT_EQ(majority(count), Style::long_short);
  EXPECT_EQ(count.count(static_cast<int>(Style::satin)) + count.count(static_cast<int>(Style::edge)), 0u)
      << "one style for a plain disk";
  EXPECT_EQ(s.components_forced_long_short, 0) << "a disk's widths are all measurable";
}

TEST(EmbroiderySegment, ShapesOfOneDrawingEachGetTheirOwnStyle) {
  cv::Mat1b line(300, 400, uchar(0)), stripe = line.clone(), disk = line.clone();
  cv::rectangle(line, cv::Rect(20, 20, 150, 2), 255, cv::FILLED);
  cv::rectangle(stripe, cv::Rect(20, 80, 150, 12), 255, cv::FILLED);
  cv::circle(disk, {280, 180}, 80, 255, cv::FILLED);
  const Segmentation s = segment_drawing(line | stripe | disk);
  EXPECT_EQ(majority(styles_under(s, line)), Style::edge);
  EXPECT_EQ(majority(styles_under(s, stripe)), Style::satin);
  EXPECT_EQ(majority(styles_under(s, disk)), Style::long_short);
  EXPECT_EQ(s.components, 3);
}

TEST(EmbroiderySegment, RaggedNoisyBlobIsForcedToLongShort) {
  // A disk with 40% of its pixels knocked out: after the median filter a spongy blob whose
  // countless ragged contour pixels cannot be paired across.
  cv::Mat1b shape(200, 200, uchar(0));
  cv::circle(shape, {100, 100}, 70, 255, cv::FILLED);
  cv::RNG rng(5);
  for (int y = 0; y < shape.rows; ++y)
    for (int x = 0; x < shape.cols; ++x)
      if (shape(y, x) && rng.uniform(0.0, 1.0) > 0.6) shape(y, x) = 0;
  const Segmentation s = segment_drawing(shape);
  EXPECT_GE(s.components_forced_long_short, 1);
  ASSERT_FALSE(s.regions.empty());
  for (const Region& r : s.regions) EXPECT_EQ(r.style, Style::long_short);
}

TEST(EmbroiderySegment, RegionMasksTileTheSewnPixelsOfARealImage) {
  const cv::Mat img = load("HappyFish.jpg");
  const Segmentation s = segment(img, ColorParams{}, LabelParams{});
  ASSERT_EQ(s.size, img.size());
  ASSERT_FALSE(s.regions.empty());
  cv::Mat1i cover(img.size(), 0);
  for (size_t i = 0; i < s.regions.size(); ++i) {
    const Region& r = s.regions[i];
    EXPECT_EQ(r.id, static_cast<int>(i));
    ASSERT_EQ(r.mask.size(), r.bbox.size());
    EXPECT_EQ(cv::countNonZero(r.mask), r.area_px);
    EXPECT_GT(r.area_px, 0);
    for (int y = 0; y < r.mask.rows; ++y)
      for (int x = 0; x < r.mask.cols; ++x) {
        if (!r.mask(y, x)) continue;
        const cv::Point q = r.bbox.tl() + cv::Point(x, y);
        ++cover(q);
        ASSERT_EQ(s.region_id(q), r.id);
        ASSERT_EQ(s.color_index(q), r.color);
        ASSERT_EQ(s.component(q), r.component);
      }
  }
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      const bool sewn = s.region_id(y, x) >= 0;
      ASSERT_EQ(cover(y, x), sewn ? 1 : 0) << "overlap or gap at " << x << "," << y;
      ASSERT_EQ(s.color_index(y, x) >= 0, sewn);
      ASSERT_EQ(s.component(y, x) >= 0, sewn);
      if (sewn) ASSERT_LT(s.color_index(y, x), static_cast<int>(s.palette.bgr.size()));
    }
  EXPECT_GT(s.components, 1);
}

TEST(EmbroiderySegment, RejectsEmptyImagesAndBadParameters) {
  const cv::Mat3b img(20, 20, cv::Vec3b(0, 0, 0));
  EXPECT_THROW(segment(cv::Mat(), ColorParams{}, LabelParams{}), std::invalid_argument);
  EXPECT_THROW(segment(cv::Mat1b(20, 20), ColorParams{}, LabelParams{}), std::invalid_argument);
  ColorParams even;
  even.median_ksize = 4;
  EXPECT_THROW(segment(img, even, LabelParams{}), std::invalid_argument);
  ColorParams too_many;
  too_many.colors = 20;
  EXPECT_THROW(segment(img, too_many, LabelParams{}), std::invalid_argument);
  LabelParams narrow;
  narrow.sW_px = 2;  // below eW
  EXPECT_THROW(segment(img, ColorParams{}, narrow), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::embroidery
