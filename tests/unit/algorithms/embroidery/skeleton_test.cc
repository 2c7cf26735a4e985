// Skeleton branches (paper 5.2) on drawn strokes: the clean-up keeps the strokes a person sees
// (a T's bar and stem, an X's two diagonals, a ring as one loop) and drops short spurs; the
// B-spline through a branch is sampled evenly and follows it.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "algorithms/embroidery/skeleton.h"

namespace atelier::embroidery {
namespace {

double span(const SkeletonBranch& b) { return cv::norm(b.pixels.front() - b.pixels.back()); }

// Largest distance of a branch pixel from the straight line through its two ends.
double straightness(const SkeletonBranch& b) {
  const cv::Point2f a = b.pixels.front(), c = b.pixels.back();
  const cv::Point2f d = (c - a) * (1.0f / static_cast<float>(cv::norm(c - a)));
  double worst = 0;
  for (const cv::Point2f& p : b.pixels) worst = std::max(worst, std::abs(static_cast<double>(d.cross(p - a))));
  return worst;
}

TEST(EmbroiderySkeleton, TGivesBarAndStem) {
  cv::Mat1b m(200, 200, uchar(0));
  cv::line(m, {20, 30}, {180, 30}, 255, 12);
  cv::line(m, {100, 30}, {100, 180}, 255, 12);
  const auto branches = skeleton_branches(m, 10);
  ASSERT_EQ(branches.size(), 2u);
  int bars = 0, stems = 0;
  for (const auto& b : branches) {
    const cv::Point2f d = b.pixels.back() - b.pixels.front();
    if (std::abs(d.x) > 130 && std::abs(d.y) < 5) ++bars;
    if (std::abs(d.y) > 120 && std::abs(d.x) < 5) ++stems;
    EXPECT_LT(straightness(b), 3.0);
  }
  EXPECT_EQ(bars, 1);
  EXPECT_EQ(stems, 1);
}

TEST(EmbroiderySkeleton, XGivesTwoStraightDiagonals) {
  cv::Mat1b m(200, 200, uchar(0));
  cv::line(m, {20, 20}, {180, 180}, 255, 10);
  cv::line(m, {180, 20}, {20, 180}, 255, 10);
  const auto branches = skeleton_branches(m, 10);
  ASSERT_EQ(branches.size(), 2u);
  for (const auto& b : branches) {
    EXPECT_GT(span(b), 190.0);  // corner to corner (226 px drawn, minus the round tips)
    EXPECT_LT(straightness(b), 3.0);
  }
}

TEST(EmbroiderySkeleton, ShortSpurIsDropped) {
  cv::Mat1b m(100, 200, uchar(0));
  cv::line(m, {20, 50}, {180, 50}, 255, 10);
  cv::rectangle(m, cv::Rect(96, 50, 9, 22), 255, cv::FILLED);  // a bump sticking out 17 px
  // With a tiny threshold the bump's spur is a branch of its own ...
  EXPECT_GT(skeleton_branches(m, 2).size(), 1u);
  // ... with 20 px it is dropped and the bar is one straight branch again.
  const auto branches = skeleton_branches(m, 20);
  ASSERT_EQ(branches.size(), 1u);
  EXPECT_GT(span(branches[0]), 140.0);
  EXPECT_LT(straightness(branches[0]), 3.0);
}

TEST(EmbroiderySkeleton, RingIsOneClosedBranch) {
  cv::Mat1b m(160, 160, uchar(0));
  cv::circle(m, {80, 80}, 50, 255, 9);
  const auto branches = skeleton_branches(m, 10);
  ASSERT_EQ(branches.size(), 1u);
  const auto& b = branches[0];
  EXPECT_TRUE(is_closed(b));
  EXPECT_LE(std::abs(b.pixels.front().x - b.pixels.back().x), 1.0f);
  EXPECT_LE(std::abs(b.pixels.front().y - b.pixels.back().y), 1.0f);
  // The loop goes all the way round: 2 pi r pixels give about 280-320 steps of 1 or sqrt 2.
  EXPECT_GT(b.pixels.size(), 220u);
  for (const cv::Point2f& p : b.pixels) EXPECT_NEAR(cv::norm(p - cv::Point2f(80, 80)), 50.0, 2.5);
}

TEST(EmbroiderySkeleton, BSplineIsEvenlySampledAndFollowsTheBranch) {
  cv::Mat1b m(200, 300, uchar(0));
  cv::ellipse(m, {150, 160}, {120, 100}, 0, 200, 340, 255, 8);  // a bent stroke
  const auto branches = skeleton_branches(m, 10);
  ASSERT_EQ(branches.size(), 1u);
  const SkeletonBranch& b = branches[0];
  const double step = 3.0, extend = 6.0;
  const SampledCurve c = fit_bspline(b, step, extend);
  ASSERT_EQ(c.points.size(), c.tangents.size());
  ASSERT_GT(c.points.size(), 50u);
  for (size_t i = 0; i < c.points.size(); ++i) {
    EXPECT_NEAR(cv::norm(c.tangents[i]), 1.0, 1e-3);
    if (i == 0) continue;
    const cv::Point2f d = c.points[i] - c.points[i - 1];
    EXPECT_NEAR(cv::norm(d), step, 0.15) << i;
    EXPECT_GT(d.dot(c.tangents[i]) / cv::norm(d), 0.95) << i;  // tangents point along
  }
  // The extension reaches past the branch's ends, in front of the first and after the last.
  EXPECT_GT(cv::norm(c.points.front() - b.pixels.back()), cv::norm(c.points.front() - b.pixels.front()));
  EXPECT_NEAR(cv::norm(c.points.front() - b.pixels.front()), extend, 2.0);
  EXPECT_NEAR(cv::norm(c.points.back() - b.pixels.back()), extend, 2.0);
  // Every sample off the extension lies on the stroke's centre line (within 1.5 px).
  const int k = static_cast<int>(std::ceil(extend / step));
  for (size_t i = k; i + k < c.points.size(); ++i) {
    double nearest = 1e9;
    for (const cv::Point2f& p : b.pixels) nearest = std::min(nearest, cv::norm(p - c.points[i]));
    EXPECT_LT(nearest, 1.5) << i;
  }
}

TEST(EmbroiderySkeleton, BSplineOfARingIsClosedWithoutExtension) {
  cv::Mat1b m(160, 160, uchar(0));
  cv::circle(m, {80, 80}, 50, 255, 9);
  const auto branches = skeleton_branches(m, 10);
  ASSERT_EQ(branches.size(), 1u);
  const SampledCurve c = fit_bspline(branches[0], 2.0, 10.0);
  // 2 pi 50 / 2 = 157 samples, none sticking out of the ring, the last one step before the first.
  EXPECT_NEAR(static_cast<double>(c.points.size()), 157.0, 6.0);
  for (const cv::Point2f& p : c.points) EXPECT_NEAR(cv::norm(p - cv::Point2f(80, 80)), 50.0, 1.5);
  EXPECT_NEAR(cv::norm(c.points.back() - c.points.front()), 2.0, 1.0);
}

}  // namespace
}  // namespace atelier::embroidery
