// Ties and the tiny-stitch filter (algorithms/embroidery/ties.h) on hand-made runs.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "algorithms/embroidery/ties.h"

namespace atelier::embroidery {
namespace {

void expect_tie(const std::vector<cv::Point2d>& run, const std::vector<cv::Point2d>& tie, cv::Point2d home,
                double min_mm) {
  ASSERT_EQ(tie.size(), 4u);
  EXPECT_LT(cv::norm(tie.back() - home), 1e-12);
  cv::Point2d at = home;
  for (const cv::Point2d& p : tie) {
    EXPECT_GT(cv::norm(p - at), min_mm);
    EXPECT_LE(cv::norm(p - at), kTieStitchMm + 1e-12);
    at = p;
  }
  (void)run;
}

TEST(EmbroideryTies, HalfStitchAlongTheRun) {
  // A 3 mm stitch, then along: the tie goes 0.75 and 1.5 mm along it and back.
  const std::vector<cv::Point2d> run = {{0, 0}, {3, 0}, {3, 3}};
  const auto in = tie_in(run, 0.1);
  expect_tie(run, in, run.front(), 0.1);
  EXPECT_NEAR(in[0].x, 0.75, 1e-12);
  EXPECT_NEAR(in[1].x, 1.5, 1e-12);
  const auto off = tie_off(run, 0.1);
  expect_tie(run, off, run.back(), 0.1);
  EXPECT_NEAR(off[1].y, 1.5, 1e-12);  // back up the last stitch
  EXPECT_NEAR(off[1].x, 3, 1e-12);
}

TEST(EmbroideryTies, ShortRunsAndFoldedPathsNeverTieInTinyStitches) {
  // 0.3 mm in all: s = 0.15.
  expect_tie({}, tie_in({{0, 0}, {0.3, 0}}, 0.1), {0, 0}, 0.1);
  // 0.15 mm in all: half would be 0.075, so back and forth over the whole run.
  const auto t = tie_in({{0, 0}, {0.15, 0}}, 0.1);
  expect_tie({}, t, {0, 0}, 0.1);
  // A satin tip folding back on itself: 0.4 out, 0.38 back, 0.4 out...
  const std::vector<cv::Point2d> fold = {{0, 0}, {0.4, 0}, {0.02, 0.05}, {0.42, 0.1}, {0.04, 0.15}, {0.44, 0.2}};
  expect_tie(fold, tie_in(fold, 0.1), fold.front(), 0.1);
  expect_tie(fold, tie_off(fold, 0.1), fold.back(), 0.1);
  // Nothing but a dot: no tie (the planner leaves such a run out).
  EXPECT_TRUE(tie_in({{0, 0}, {0.05, 0}, {0.02, 0.03}}, 0.1).empty());
}

TEST(EmbroideryTies, TinyStitchesAreDroppedNotMoved) {
  std::vector<cv::Point2d> run = {{0, 0}, {0.05, 0}, {0.1, 0}, {0.5, 0}, {0.55, 0}, {3, 0}, {3, 0}};
  const std::vector<cv::Point2d> before = run;
  EXPECT_EQ(drop_tiny_stitches(run, 0.1), 4);
  ASSERT_EQ(run.size(), 3u);
  // Every kept point is one of the originals, in order, each more than 0.1 mm from the last.
  EXPECT_EQ(run[0], before[0]);
  EXPECT_EQ(run[1], before[3]);
  EXPECT_EQ(run[2], before[5]);
}

}  // namespace
}  // namespace atelier::embroidery
