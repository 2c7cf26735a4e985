// The lace fitness terms (algorithms/lace/fitness.h, Ekart 2007 sections 4-7) on hand-drawn
// charts.
#include <gtest/gtest.h>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/fitness.h"
#include "algorithms/lace/stitch_tree.h"
#include "algorithms/lace/symbols.h"
#include "tests/support/lace_test_charts.h"

namespace atelier::lace {
namespace {

using namespace test;  // row(), knit() and the charts of lace_test_charts.h

TEST(LaceFitness, AllPlainChartHasNoHolesAndFullKnitLength) {
  const Chart plain{{knit(6), knit(6), knit(6), knit(6)}};
  const Evaluation e = evaluate(plain, 6, Weights{}, 2);
  EXPECT_TRUE(e.constraints.ok());
  EXPECT_DOUBLE_EQ(e.objectives.holes, 0.0);
  EXPECT_DOUBLE_EQ(e.objectives.knit_length, 1.0);
  EXPECT_DOUBLE_EQ(e.objectives.depth, 0.0);
  // No motif, so no symmetry to reward: plain knitting must not win on a trivial mirror.
  EXPECT_DOUBLE_EQ(e.objectives.symmetry, 0.0);
  // Eq. 2 with the default weights: 0.5 * knit_length, minus 50 * how far the yarn-over share
  // (0) is below the band's 10 % (plain knitting is not lace).
  EXPECT_DOUBLE_EQ(e.objectives.yo_band_distance, 0.10);
  EXPECT_DOUBLE_EQ(e.score, 0.5 - 50 * 0.10);
}

TEST(LaceFitness, ThreeYarnOversSideBySideIsOneExcess) {
  // 7 cast on: "k, yo, yo, yo, sk2p, k2tog, k" -- balanced, but three yarn-overs together.
  const Chart chart{{row({"k", "yo", "yo", "yo", "sk2p", "k2tog", "k"})}};
  ASSERT_TRUE(knittable(chart, 7));
  const Evaluation e = evaluate(chart, 7, Weights{}, 2);
  EXPECT_EQ(e.constraints.adjacent_yo_excess, 1);
  EXPECT_EQ(e.constraints.balance_error, 0);
  EXPECT_FALSE(e.constraints.ok());
  // Worse than any feasible chart (whose score is >= -(yo_band + width_change)).
  EXPECT_LT(e.score, -(Weights{}.yo_band + Weights{}.width_change));

  // Runs that meet across the repeat edge count: "yo, k2tog, k, k2tog, yo, yo" tiles to 3.
  const Chart wraps{{row({"yo", "k2tog", "k", "k2tog", "yo", "yo"})}};
  EXPECT_EQ(evaluate(wraps, 6, Weights{}, 2).constraints.adjacent_yo_excess, 1);
}

TEST(LaceFitness, BalanceAndWidthViolationsAreCountedInStitches) {
  // 4 cast on, a yarn-over nobody takes back: one stitch too many at the end.
  const Chart wide{{row({"k", "yo", "k", "k", "k"})}};
  const Evaluation e = evaluate(wide, 4, Weights{}, 2);
  EXPECT_EQ(e.constraints.balance_error, 1);
  EXPECT_EQ(e.constraints.width_excess, 0);
  // Rows 4 -> 7 -> 4 wide with tolerance 2: the middle row is 1 over (against the cast-on and
  // against the first row).
  const Chart bulge{{knit(4), row({"yo", "k", "yo", "k", "yo", "k", "k"}),
                     row({"sk2p", "k", "k2tog", "k"})}};
  ASSERT_TRUE(knittable(bulge, 4));
  const Evaluation b = evaluate(bulge, 4, Weights{}, 2);
  EXPECT_EQ(b.constraints.balance_error, 0);
  EXPECT_EQ(b.constraints.width_excess, 2);
  EXPECT_EQ(evaluate(bulge, 4, Weights{}, 3).constraints.width_excess, 0);
  EXPECT_THROW(evaluate(Chart{}, 4, Weights{}, 2), std::invalid_argument);
  EXPECT_THROW(evaluate(Chart{{knit(4), knit(5)}}, 4, Weights{}, 2), std::invalid_argument);
}

TEST(LaceFitness, MirrorSymmetryAndNormalisedHoles) {
  // A mirror-symmetric row: "k, yo, ssk, k, k2tog, yo, k" (the mirror of a ssk is a k2tog).
  const Chart mirror{{row({"k", "yo", "ssk", "k", "k2tog", "yo", "k"})}};
  ASSERT_TRUE(knittable(mirror, 7));
  const Evaluation m = evaluate(mirror, 7, Weights{}, 0);
  EXPECT_TRUE(m.constraints.ok());
  EXPECT_DOUBLE_EQ(m.objectives.symmetry, 1.0);
  EXPECT_DOUBLE_EQ(m.objectives.holes, 1.5 * 2 / 7);
  // Both decreases slanting the same way break the mirror at those two of the four motif cells.
  const Chart slanted{{row({"k", "yo", "k2tog", "k", "k2tog", "yo", "k"})}};
  EXPECT_DOUBLE_EQ(evaluate(slanted, 7, Weights{}, 0).objectives.symmetry, 2.0 / 4);
  // The densest lace: "yo, sk2p, yo" everywhere reaches holes 1.
  const Chart dense{{row({"yo", "sk2p", "yo"}, 2)}};
  EXPECT_DOUBLE_EQ(evaluate(dense, 6, Weights{}, 0).objectives.holes, 1.0);

  const Evaluation h = evaluate(horseshoe_chart(), 10, Weights{}, 0);
  EXPECT_TRUE(h.constraints.ok());
  EXPECT_DOUBLE_EQ(h.objectives.holes, 1.5 * 8 / 40);
}

TEST(LaceFitness, KnitLengthAndDepthFollowTheTrees) {
  // 3 stitches, 4 rows, plain but for "yo, k2tog, k" in row 1.
  const Chart chart{{knit(3), row({"yo", "k2tog", "k"}), knit(3), knit(3)}};
  ASSERT_TRUE(knittable(chart, 3));
  const Evaluation e = evaluate(chart, 3, Weights{}, 0);
  // Plain stitches: 3 + 1 + 3 + 3 = 10. Runs: the k of row 1 continues the run of its column
  // from row 0 (1 run of 4 rows); rows 2-3 over the yo and over the k2tog make 2 runs of 2;
  // row 0 under the k2tog makes 2 runs of 1. 10 / 5 runs = 2 rows, / 4 rows = 0.5.
  EXPECT_DOUBLE_EQ(e.objectives.knit_length, 0.5);
  // Trees (last-row stitches): the yo in row 1 is 3 rows below the root (reach 3), so is the
  // k2tog; the third tree is all plain (0). (3 + 3 + 0) / 3 / 4.
  EXPECT_DOUBLE_EQ(e.objectives.depth, 0.5);
}

TEST(LaceFitness, YarnOverShareOutsideTheBandIsMinimised) {
  // 12 stitches, 4 rows. In the band: one "yo, k2tog" a row = 4 / 48 = 8 %, below 10 %.
  const Row eyelet = cat({row({"yo", "k2tog"}), knit(10)});
  const Chart sparse{{eyelet, eyelet, eyelet, eyelet}};
  const Evaluation few = evaluate(sparse, 12, Weights{}, 2);
  EXPECT_DOUBLE_EQ(few.objectives.yo_share, 4.0 / 48);
  EXPECT_NEAR(few.objectives.yo_band_distance, 0.10 - 4.0 / 48, 1e-12);
  // "yo, sk2p, yo" x 4 = 8 holes of 12 a row: 67 %, far above 25 %.
  const Row mesh = row({"yo", "sk2p", "yo"}, 4);
  const Chart dense{{mesh, mesh, mesh, mesh}};
  const Evaluation many = evaluate(dense, 12, Weights{}, 2);
  EXPECT_TRUE(many.constraints.ok());
  EXPECT_NEAR(many.objectives.yo_band_distance, 8.0 / 12 - 0.25, 1e-12);
  // Eq. 2's holes term alone prefers the mesh (that was the random-mesh look); with the band
  // term the mesh scores below a chart in the band.
  Weights holes_only{};
  holes_only.yo_band = 0;
  EXPECT_GT(evaluate(dense, 12, holes_only, 2).score, evaluate(sparse, 12, holes_only, 2).score);
  const Row in_band = cat({knit(3), row({"yo", "k2tog", "k", "k", "ssk", "yo"}), knit(3)});  // 2 / 12 = 17 %
  const Chart lace{{in_band, in_band, in_band, in_band}};
  const Evaluation good = evaluate(lace, 12, Weights{}, 2);
  EXPECT_DOUBLE_EQ(good.objectives.yo_band_distance, 0.0);
  EXPECT_GT(good.score, many.score);
  // Vertical lines of eyelets: every hole in a line.
  EXPECT_DOUBLE_EQ(good.objectives.hole_lines, 1.0);
  EXPECT_DOUBLE_EQ(good.objectives.symmetry, 1.0);
}

TEST(LaceFitness, WidthChangeIsMinimised) {
  // Row 0 widens 6 -> 7 ("yo" added), row 1 narrows back: mean |width - 6| / 6 = 0.5 / 6.
  const Chart wider{{row({"k", "k", "yo", "k", "k", "k", "k"}), row({"k", "k", "k2tog", "k", "k", "k"})}};
  ASSERT_TRUE(knittable(wider, 6));
  const Evaluation e = evaluate(wider, 6, Weights{}, 2);
  EXPECT_TRUE(e.constraints.ok());
  EXPECT_DOUBLE_EQ(e.objectives.width_change, (1.0 + 0.0) / 2 / 6);
}

}  // namespace
}  // namespace atelier::lace
