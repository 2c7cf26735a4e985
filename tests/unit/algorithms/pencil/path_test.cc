// The path of a human-like pencil line (Meraj et al. 2008, section 3.1): it starts and ends at
// its end points, strays from the straight segment by no more than the squiggle allows, follows
// the minimum-jerk timing of table 1, and is reproducible from its seed.
#include <gtest/gtest.h>

#include <cmath>

#include "algorithms/pencil/path.h"

namespace atelier::pencil {
namespace {

// Distance of p from the straight line through a and b.
double off_line(cv::Point2d p, cv::Point2d a, cv::Point2d b) {
  const cv::Point2d d = b - a;
  return std::abs(d.x * (p.y - a.y) - d.y * (p.x - a.x)) / std::hypot(d.x, d.y);
}

TEST(PencilPath, TimeStepFollowsTableOne) {
  EXPECT_EQ(time_step(50), 0.5);
  EXPECT_EQ(time_step(200), 0.5);
  EXPECT_EQ(time_step(201), 0.3);
  EXPECT_EQ(time_step(400), 0.3);
  EXPECT_EQ(time_step(401), 0.2);
  // So a 150 px line has controls at t = 0, 0.5, 1, 1.5, 2; 300 px at 0, 0.3, ..., 1.8, 2.
  std::mt19937_64 rng(1);
  EXPECT_EQ(control_points({0, 0}, {150, 0}, 0, rng).size(), 5u);
  EXPECT_EQ(control_points({0, 0}, {300, 0}, 0, rng).size(), 8u);
  EXPECT_EQ(control_points({0, 0}, {1000, 0}, 0, rng).size(), 11u);
}

TEST(PencilPath, MinimumJerkIsSlowAtTheEndsAndFastInTheMiddle) {
  const cv::Point2d a(10, 20), b(210, 20);
  EXPECT_NEAR(cv::norm(min_jerk(a, b, 0) - a), 0, 1e-12);
  EXPECT_NEAR(cv::norm(min_jerk(a, b, kFinalTime) - b), 0, 1e-9);
  EXPECT_NEAR(min_jerk(a, b, 1).x, 110, 1e-9) << "halfway in time is halfway in space";
  // The first and last quarter of the time cover much less ground than the middle half.
  const double first = min_jerk(a, b, 0.5).x - a.x, middle = min_jerk(a, b, 1.5).x - min_jerk(a, b, 0.5).x;
  EXPECT_NEAR(first, 200 * 0.103515625, 1e-9);  // 10 tau^3 - 15 tau^4 + 6 tau^5 at tau = 1/4
  EXPECT_GT(middle, 3 * first);
}

TEST(PencilPath, ALineStartsAndEndsAtItsEndPointsAndStaysWithinTheSquiggle) {
  std::mt19937_64 pick(7);
  std::uniform_real_distribution<double> coord(-500, 1500);
  for (int i = 0; i < 300; ++i) {
    const cv::Point2d a(coord(pick), coord(pick)), b(coord(pick), coord(pick));
    PathParams p;
    p.squiggle = i % 3 == 0 ? 5.0 : 2.0;
    const HumanPath h = human_path(a, b, p, 1000 + i);
    ASSERT_GE(h.path.size(), 2u);
    EXPECT_LT(cv::norm(h.path.front() - a), 1.0);
    EXPECT_LT(cv::norm(h.path.back() - b), 1.0);
    double worst = 0, longest_step = 0;
    for (size_t k = 0; k < h.path.size(); ++k) {
      worst = std::max(worst, off_line(h.path[k], a, b));
      if (k > 0) longest_step = std::max(longest_step, cv::norm(h.path[k] - h.path[k - 1]));
    }
    EXPECT_LE(worst, max_deviation(p.squiggle) + 1e-9) << "line " << i;
    EXPECT_LE(longest_step, p.spacing_px + 1e-9) << "line " << i;
    // The control points themselves stray by at most D.
    for (const cv::Point2d& c : h.control) EXPECT_LE(off_line(c, a, b), p.squiggle + 1e-9);
  }
}

TEST(PencilPath, TheSquiggleShowsAndZeroSquiggleIsStraight) {
  const cv::Point2d a(0, 0), b(600, 300);
  PathParams straight;
  straight.squiggle = 0;
  for (const cv::Point2d& q : human_path(a, b, straight, 3).path) EXPECT_LT(off_line(q, a, b), 1e-9);
  // With the paper's D = 5 a long line visibly wanders (over 1 px somewhere), every time.
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    double worst = 0;
    for (const cv::Point2d& q : human_path(a, b, PathParams{}, seed).path) worst = std::max(worst, off_line(q, a, b));
    EXPECT_GT(worst, 1.0) << "seed " << seed;
  }
}

TEST(PencilPath, SameSeedSameLineOtherSeedOtherLine) {
  const cv::Point2d a(12, 40), b(250, 90);
  const HumanPath one = human_path(a, b, PathParams{}, 42), again = human_path(a, b, PathParams{}, 42);
  EXPECT_EQ(one.path, again.path);
  const HumanPath other = human_path(a, b, PathParams{}, 43);
  ASSERT_EQ(one.control.size(), other.control.size());
  double differ = 0;
  for (size_t k = 0; k < one.control.size(); ++k) differ = std::max(differ, cv::norm(one.control[k] - other.control[k]));
  EXPECT_GT(differ, 0.5);
}

TEST(PencilPath, LinesOfAnyLength) {
  // A point, a one-pixel stroke and a very long line.
  EXPECT_EQ(human_path({5, 5}, {5, 5}, PathParams{}, 1).path, std::vector<cv::Point2d>{cv::Point2d(5, 5)});
  const HumanPath tiny = human_path({5, 5}, {6, 5}, PathParams{}, 1);
  EXPECT_EQ(tiny.path.back(), cv::Point2d(6, 5));
  const HumanPath huge = human_path({0, 0}, {20000, 0}, PathParams{}, 1);
  EXPECT_EQ(huge.control.size(), 11u);
  EXPECT_EQ(huge.path.back(), cv::Point2d(20000, 0));
}

TEST(PencilPath, BadParametersAreRefused) {
  PathParams p;
  p.squiggle = -1;
  EXPECT_THROW(human_path({0, 0}, {10, 0}, p, 1), std::invalid_argument);
  p = {};
  p.spacing_px = 0;
  EXPECT_THROW(human_path({0, 0}, {10, 0}, p, 1), std::invalid_argument);
  EXPECT_THROW(human_path({0, 0}, {NAN, 0}, PathParams{}, 1), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::pencil
