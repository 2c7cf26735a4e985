// draw_sketch: segments redrawn as pencil lines; the drawing does not depend on the thread count.
#include <gtest/gtest.h>

#include <random>

#include "algorithms/pencil/sketch.h"
#include "convert/sketch/pencil_profile_file.h"

namespace atelier::pencil {
namespace {

std::vector<Segment> random_segments(int n, double length, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> x(20, 480), angle(0, 2 * CV_PI);
  std::vector<Segment> out;
  for (int i = 0; i < n; ++i) {
    const cv::Point2d from(x(rng), x(rng));
    const double a = angle(rng);
    out.push_back({from, from + length * cv::Point2d(std::cos(a), std::sin(a))});
  }
  return out;
}

TEST(PencilSketch, TheDrawingIsTheSameForAnyThreadCount) {
  const std::vector<Segment> strokes = random_segments(300, 80, 1), hatching = random_segments(50, 30, 2);
  const PencilProfile pencil = shipped_pencil("6B");
  const SketchDrawing one = draw_sketch({500, 500}, 1.0, strokes, hatching, {}, pencil, 9, {}, 1);
  for (int threads : {2, 3, 7}) {
    const SketchDrawing many = draw_sketch({500, 500}, 1.0, strokes, hatching, {}, pencil, 9, {}, threads);
    EXPECT_EQ(cv::countNonZero(one.canvas != many.canvas), 0) << threads << " threads";
    ASSERT_EQ(many.lines.size(), one.lines.size());
    for (size_t i = 0; i < one.lines.size(); ++i) {
      EXPECT_EQ(many.lines[i].path, one.lines[i].path) << i;
      EXPECT_EQ(many.lines[i].hatch, i >= strokes.size()) << i;
    }
  }
  EXPECT_GT(cv::countNonZero(one.canvas < 128), 5000) << "the lines are on the paper";
}

TEST(PencilSketch, EveryLineRunsBetweenItsEndPointsAndProgressReachesOne) {
  const std::vector<Segment> strokes = random_segments(40, 150, 3);
  std::vector<double> seen;
  const SketchDrawing d = draw_sketch({500, 500}, 2.0, strokes, {}, {}, shipped_pencil("HB"), 1,
                                      [&](double f) { seen.push_back(f); });
  ASSERT_EQ(d.lines.size(), strokes.size());
  EXPECT_EQ(d.canvas.size(), cv::Size(1000, 1000));
  for (size_t i = 0; i < strokes.size(); ++i) {
    EXPECT_LT(cv::norm(d.lines[i].path.front() - strokes[i].from * 2.0), 1.0);
    EXPECT_LT(cv::norm(d.lines[i].path.back() - strokes[i].to * 2.0), 1.0);
  }
  ASSERT_FALSE(seen.empty());
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_DOUBLE_EQ(seen.back(), 1.0);
  EXPECT_THROW(draw_sketch({500, 500}, 1.0, strokes, {}, {}, shipped_pencil("HB"), 1, {}, 0), std::invalid_argument);
}

TEST(PencilSketch, KeepLongestKeepsStrokesFirstInTheirOrder) {
  std::vector<Segment> strokes = {{{0, 0}, {10, 0}}, {{0, 0}, {50, 0}}, {{0, 0}, {5, 0}}, {{0, 0}, {30, 0}}};
  std::vector<Segment> hatching = {{{0, 0}, {100, 0}}, {{0, 0}, {3, 0}}};
  EXPECT_EQ(keep_longest(&strokes, &hatching, 3), (std::pair<std::size_t, std::size_t>{3, 0}));
  ASSERT_EQ(strokes.size(), 3u);
  EXPECT_EQ(strokes[0].to.x, 10);  // the order a hand draws in is kept
  EXPECT_EQ(strokes[1].to.x, 50);
  EXPECT_EQ(strokes[2].to.x, 30);
  EXPECT_TRUE(hatching.empty());
}

}  // namespace
}  // namespace atelier::pencil
