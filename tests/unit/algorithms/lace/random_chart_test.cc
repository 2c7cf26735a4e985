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

}  // namespace
}  // namespace atelier::lace
