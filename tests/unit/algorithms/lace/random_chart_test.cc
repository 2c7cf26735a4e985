// Random lace charts (algorithms/lace/random_chart.h): row by row, within the constraints.
#include <gtest/gtest.h>

#include <random>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/fitness.h"
#include "algorithms/lace/random_chart.h"
#include "algorithms/lace/symbols.h"
#include "tests/support/lace_test_charts.h"

namespace atelier::lace {
namespace {

using namespace test;  // row(), knit() and the charts of lace_test_charts.h

TEST(LaceRandomChart, RowByRowChartsSatisfyTheConstraints) {
  std::mt19937_64 rng(7);
  for (int i = 0; i < 200; ++i) {
    const int width = 2 + i % 15, rows = 1 + i % 9;
    const Chart c = random_feasible_chart(width, rows, rng);
    ASSERT_TRUE(knittable(c, width)) << knittable(c, width).why;
    EXPECT_TRUE(yarn_over_balance(c));
    EXPECT_TRUE(adjacent_yarn_overs_ok(c, /*repeated=*/true));
    EXPECT_TRUE(width_ok(c, 0));
    EXPECT_TRUE(evaluate(c, width, Weights{}, 0).constraints.ok());
  }
}

TEST(LaceRandomChart, SymmetricChartsAreMirrorSymmetricAndFeasible) {
  std::mt19937_64 rng(17);
  int with_lace = 0;
  for (int i = 0; i < 200; ++i) {
    const int width = 1 + i % 15, rows = 1 + i % 7;
    const Chart c = random_symmetric_chart(width, rows, rng);
    ASSERT_EQ(static_cast<int>(c.rows.size()), rows);
    const Evaluation e = evaluate(c, width, Weights{}, 0);
    EXPECT_TRUE(e.constraints.ok()) << "chart " << i;
    for (const Row& r : c.rows) {
      ASSERT_EQ(static_cast<int>(r.size()), width);
      for (int j = 0; j < width; ++j) {
        const Symbol m = r[width - 1 - j];
        const Symbol mirror = m == Symbol::k2tog ? Symbol::ssk : m == Symbol::ssk ? Symbol::k2tog : m;
        ASSERT_EQ(r[j], mirror) << "chart " << i << " cell " << j;
      }
    }
    if (e.objectives.holes > 0) {
      ++with_lace;
      EXPECT_DOUBLE_EQ(e.objectives.symmetry, 1.0);
    }
  }
  EXPECT_GT(with_lace, 120);  // widths 1-3 are often plain
  EXPECT_THROW(random_symmetric_chart(0, 3, rng), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::lace
