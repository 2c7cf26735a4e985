// dither/solver "auto" by measurement (algorithms/knit/auto_choice.h): the winner is the best
// measured complete candidate, the same whatever the thread count, and is the grid returned.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "algorithms/knit/auto_choice.h"
#include "algorithms/knit/floats.h"
#include "algorithms/knit/similarity.h"
#include "algorithms/knit/stitch_grid.h"
#include "tests/support/knit_test_images.h"

namespace atelier::knit {
namespace {

TEST(KnitAutoChoice, BestMeasuredCandidateIndependentOfThreads) {
  const cv::Mat gray = to_stitch_grid(testing::load_test_image("pic3.png"), GaugeParams{90, 28, 36});
  FloatRules rules;
  SolverParams params;
  params.seed = 3;
  const AutoResult one = choose_by_measurement(gray, rules, auto_dither_candidates(),
                                               auto_solver_candidates(), 128, params, 1);
  const AutoResult two = choose_by_measurement(gray, rules, auto_dither_candidates(),
                                               auto_solver_candidates(), 128, params, 2);
  ASSERT_EQ(one.candidates.size(), 16u);
  EXPECT_EQ(one.chosen, two.chosen);
  EXPECT_EQ(cv::countNonZero(one.grid != two.grid), 0);
  for (size_t i = 0; i < one.candidates.size(); ++i) {
    EXPECT_EQ(one.candidates[i].similarity, two.candidates[i].similarity) << i;
    EXPECT_EQ(one.candidates[i].violations, 0) << i;
    EXPECT_GE(one.candidates[one.chosen].similarity, one.candidates[i].similarity) << i;
  }
  // The grid returned is the chosen pair's: solved, and measuring what was reported.
  EXPECT_EQ(count_violations(one.grid, rules), 0);
  EXPECT_DOUBLE_EQ(blurred_ssim(gray, one.grid), one.candidates[one.chosen].similarity);
  EXPECT_EQ(one.stats.flips, one.candidates[one.chosen].flips);
  EXPECT_NE(one.reason.find("blurred SSIM"), std::string::npos);
  EXPECT_THROW(choose_by_measurement(gray, rules, {Dither::automatic}, {Solver::gsat}, 128, params),
               std::invalid_argument);
  EXPECT_THROW(choose_by_measurement(gray, rules, {}, {Solver::gsat}, 128, params), std::invalid_argument);
}

// Incomplete candidates only (Random Walk): the fewest violations win, and the reason says so.
TEST(KnitAutoChoice, WithoutACompleteCandidateTheFewestViolationsWin) {
  const cv::Mat gray = to_stitch_grid(testing::load_test_image("fruits.jpg"), GaugeParams{80, 28, 36});
  FloatRules rules;
  const AutoResult r = choose_by_measurement(gray, rules, auto_dither_candidates(), {Solver::none},
                                             128, SolverParams{}, 2);
  long fewest = r.candidates[0].violations;
  for (const AutoCandidate& c : r.candidates) fewest = std::min(fewest, c.violations);
  ASSERT_GT(fewest, 0);
  EXPECT_EQ(r.candidates[r.chosen].violations, fewest);
  EXPECT_NE(r.reason.find("fewest violations"), std::string::npos);
}

}  // namespace
}  // namespace atelier::knit
