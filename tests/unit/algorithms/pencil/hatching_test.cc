// Hatching for sketch jobs (algorithms/pencil/hatching.h): dark regions are hatched inside
// their outline, evenly, crossed where darker.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>

#include "algorithms/pencil/hatching.h"
#include "tests/unit/algorithms/pencil/strokes_fixture.h"

namespace atelier::pencil {
namespace {

using testing::length;
using testing::load;

constexpr double kEps = 1e-6;

// A 200 x 200 white grey image with the square [50, 149]^2 at `level` (0 black .. 1 white).
cv::Mat square(double level, int side = 100) {
  cv::Mat image(200, 200, CV_8UC1, cv::Scalar(255));
  image(cv::Rect(50, 50, side, side)).setTo(cv::Scalar(std::round(level * 255)));
  return image;
}

// Direction of a segment in degrees, folded into [0, 180).
double direction(const Segment& s) {
  double a = std::atan2(s.to.y - s.from.y, s.to.x - s.from.x) * 180 / CV_PI;
  a = std::fmod(a + 360.0, 180.0);
  return a > 180 - kEps ? a - 180 : a;
}

// Hatch segments grouped by direction, each group's lines by offset along the normal.
std::map<long, std::map<long, int>> lines_by_direction(const std::vector<Segment>& hatch, double spacing) {
  std::map<long, std::map<long, int>> out;
  for (const Segment& s : hatch) {
    const double a = direction(s) * CV_PI / 180;
    const cv::Point2d n(-std::sin(a), std::cos(a));
    const double k = s.from.dot(n) / spacing;
    EXPECT_NEAR(k, std::round(k), 1e-6) << "a hatch line off the spacing grid";
    EXPECT_NEAR(s.to.dot(n) / spacing, k, 1e-6) << "a hatch segment that is not straight along its line";
    ++out[std::lround(direction(s))][std::lround(k)];
  }
  return out;
}

void expect_inside_square(const std::vector<Segment>& hatch, int side = 100) {
  for (const Segment& s : hatch)
    for (cv::Point2d p : {s.from, s.to}) {
      EXPECT_GE(p.x, 50 - 1.0);
      EXPECT_LE(p.x, 50 + side - 1 + 1.0);
      EXPECT_GE(p.y, 50 - 1.0);
      EXPECT_LE(p.y, 50 + side - 1 + 1.0);
    }
}

TEST(PencilHatching, AMidGreySquareIsHatchedInsideAtTheAngleAndSpacing) {
  const HatchParams params;  // 45 degrees, 6 px, dark below 0.35, crossed below 0.15
  const std::vector<Segment> hatch = hatch_lines(square(0.25), params);
  ASSERT_FALSE(hatch.empty());
  expect_inside_square(hatch);
  const auto groups = lines_by_direction(hatch, params.spacing_px);
  ASSERT_EQ(groups.size(), 1u) << "0.25 is not dark enough to cross";
  EXPECT_EQ(groups.begin()->first, 45);
  // One segment per line across the convex square, on consecutive lines of the grid: none
  // skipped. The square's extent across 45-degree lines is 100 * sqrt(2) = 141 px, ~23 lines
  // less the corner runs under min_length_px.
  const std::map<long, int>& lines = groups.begin()->second;
  EXPECT_GE(lines.size(), 20u);
  long previous = lines.begin()->first - 1;
  for (const auto& [k, count] : lines) {
    EXPECT_EQ(count, 1) << "line " << k;
    EXPECT_EQ(k, previous + 1) << "a hatch line is missing";
    previous = k;
  }
  for (const Segment& s : hatch) EXPECT_GE(length(s), params.min_length_px);
  // The longest run crosses the square's diagonal, ~141 px (the blur trims ~2 px at each end).
  double longest = 0;
  for (const Segment& s : hatch) longest = std::max(longest, length(s));
  EXPECT_NEAR(longest, 100 * std::sqrt(2.0), 8.0);
}

TEST(PencilHatching, ABlackSquareIsCrossHatched) {
  HatchParams params;
  params.angle_deg = 30, params.spacing_px = 8;
  const std::vector<Segment> hatch = hatch_lines(square(0.0), params);
  expect_inside_square(hatch);
  const auto groups = lines_by_direction(hatch, params.spacing_px);
  ASSERT_EQ(groups.size(), 2u);
  EXPECT_EQ(groups.begin()->first, 30);
  EXPECT_EQ(std::next(groups.begin())->first, 120);
  for (const auto& [angle, lines] : groups) EXPECT_GE(lines.size(), 12u) << angle;  // ~100 * 1.37 / 8 = 17
  // Layer 1 first, then the crossing layer (a hand finishes one direction before the next).
  EXPECT_NEAR(direction(hatch.front()), 30, kEps);
  EXPECT_NEAR(direction(hatch.back()), 120, kEps);
}

TEST(PencilHatching, HorizontalHatchingFollowsTheSpacing) {
  HatchParams params;
  params.angle_deg = 0, params.spacing_px = 10, params.cross_level = 0;
  const std::vector<Segment> hatch = hatch_lines(square(0.0), params);
  expect_inside_square(hatch);
  // Rows 60, 70, ..., 140 of the square [50, 149]; row 50 lies where the smoothing blurs the
  // square's border above dark_level, so it may be left out.
  ASSERT_GE(hatch.size(), 9u);
  ASSERT_LE(hatch.size(), 10u);
  for (size_t i = 0; i < hatch.size(); ++i) {
    EXPECT_NEAR(std::fmod(hatch[i].from.y, 10.0), 0, kEps);
    if (i > 0) EXPECT_NEAR(hatch[i].from.y - hatch[i - 1].from.y, 10, kEps);
    EXPECT_NEAR(hatch[i].to.y, hatch[i].from.y, kEps);
    EXPECT_LT(hatch[i].from.x, hatch[i].to.x) << "drawn left to right";
    EXPECT_NEAR(length(hatch[i]), 99, 4.0);
  }
  EXPECT_NEAR(hatch.back().from.y, 140, kEps);
}

TEST(PencilHatching, NothingOnPaperLightGreyOrSpecks) {
  EXPECT_TRUE(hatch_lines(cv::Mat(200, 200, CV_8UC1, cv::Scalar(255)), HatchParams{}).empty());
  EXPECT_TRUE(hatch_lines(square(0.5), HatchParams{}).empty()) << "0.5 is lighter than dark_level";
  EXPECT_TRUE(hatch_lines(square(0.0, 7), HatchParams{}).empty()) << "a 7 x 7 speck is under min_area_px";
  cv::Mat transparent(200, 200, CV_8UC4, cv::Scalar(0, 0, 0, 0));
  EXPECT_TRUE(hatch_lines(transparent, HatchParams{}).empty()) << "transparent is paper";
}

TEST(PencilHatching, HatchingOnARealImageLiesInItsDarkRegions) {
  const cv::Mat image = load("pic1.png");
  const std::vector<Segment> hatch = hatch_lines(image, HatchParams{});
  std::printf("pic1: %zu hatch segments\n", hatch.size());
  ASSERT_GT(hatch.size(), 100u);  // six black shapes
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  for (const Segment& s : hatch)
    for (double t : {0.0, 0.25, 0.5, 0.75, 1.0}) {
      const cv::Point2d p = s.from + t * (s.to - s.from);
      EXPECT_LT(grey.at<uchar>(cvRound(p.y), cvRound(p.x)), 128) << "hatching on paper at " << p;
    }
}

TEST(PencilHatching, BadParametersAndImagesThrow) {
  const cv::Mat image = square(0.0);
  auto throws_naming = [&](void (*change)(HatchParams&), const std::string& name) {
    HatchParams p;
    change(p);
    try {
      hatch_lines(image, p);
      ADD_FAILURE() << name << ": no throw";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  };
  throws_naming([](HatchParams& p) { p.dark_level = 1.5; }, "dark_level");
  throws_naming([](HatchParams& p) { p.cross_level = 0.5; }, "cross_level");  // above dark_level
  throws_naming([](HatchParams& p) { p.spacing_px = 0; }, "spacing_px");
  throws_naming([](HatchParams& p) { p.angle_deg = INFINITY; }, "angle_deg");
  throws_naming([](HatchParams& p) { p.min_length_px = -1; }, "min_length_px");
  throws_naming([](HatchParams& p) { p.min_area_px = -1; }, "min_area_px");
  EXPECT_THROW(hatch_lines(cv::Mat(), HatchParams{}), std::invalid_argument);
  EXPECT_THROW(hatch_lines(cv::Mat(10, 10, CV_16UC1, cv::Scalar(0)), HatchParams{}), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::pencil
