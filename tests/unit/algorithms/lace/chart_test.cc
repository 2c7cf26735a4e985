// Lace charts (algorithms/lace/chart.h, Ekart 2007): the knittability and constraint checks.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/stitch_tree.h"
#include "algorithms/lace/symbols.h"
#include "tests/unit/algorithms/lace/chart_fixture.h"
#include "tests/support/lace_test_charts.h"

namespace atelier::lace {
namespace {

using namespace test;  // row(), knit() and the charts of lace_test_charts.h

TEST(LaceChart, RealChartsAreKnittableFromTheirCastOn) {
  EXPECT_TRUE(knittable(eyelet_chart(), 8));
  EXPECT_TRUE(knittable(feather_and_fan_chart(), 18));
  EXPECT_TRUE(knittable(horseshoe_chart(), 10));
  EXPECT_EQ(produced(feather_and_fan_chart().rows[1]), 18);
  EXPECT_EQ(consumed(feather_and_fan_chart().rows[1]), 18);
}

TEST(LaceChart, UnknittableChartIsRefusedNamingTheRow) {
  Chart bad = eyelet_chart();
  bad.rows[2][3] = Symbol::k2tog;  // row 2 now wants 9 stitches; row 1 made 8
  const Knittability k = knittable(bad, 8);
  EXPECT_FALSE(k);
  EXPECT_EQ(k.bad_row, 2);
  EXPECT_NE(k.why.find("row 2"), std::string::npos) << k.why;
  EXPECT_NE(k.why.find("9"), std::string::npos) << k.why;
  EXPECT_NE(k.why.find("8"), std::string::npos) << k.why;

  try {
    encode(bad, 8);
    FAIL() << "an unknittable chart was encoded";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("row 2"), std::string::npos) << e.what();
  }

  // Wrong cast-on: row 0 is at fault.
  const Knittability wrong_cast_on = knittable(eyelet_chart(), 10);
  EXPECT_FALSE(wrong_cast_on);
  EXPECT_EQ(wrong_cast_on.bad_row, 0);
  EXPECT_NE(wrong_cast_on.why.find("cast-on"), std::string::npos) << wrong_cast_on.why;
  EXPECT_FALSE(knittable(Chart{}, 8));
}

TEST(LaceChart, YarnOverBalanceFollowsEquationOne) {
  EXPECT_TRUE(yarn_over_balance(eyelet_chart()));
  EXPECT_TRUE(yarn_over_balance(feather_and_fan_chart()));
  EXPECT_TRUE(yarn_over_balance(horseshoe_chart()));  // 2 yo per sk2p

  // A yarn-over with nothing taking it back: the fabric widens.
  EXPECT_FALSE(yarn_over_balance(Chart{{row({"k", "yo", "k"})}}));
  // Horseshoe with its double decrease made single: one stitch too many per row.
  Chart single = horseshoe_chart();
  single.rows[0][4] = Symbol::k2tog;
  EXPECT_FALSE(yarn_over_balance(single));
}

TEST(LaceChart, AtMostTwoYarnOversSideBySide) {
  EXPECT_EQ(max_adjacent_yarn_overs(row({"k", "yo", "yo", "sk2p", "k"})), 2);
  EXPECT_EQ(max_adjacent_yarn_overs(row({"k", "yo", "yo", "yo", "sk2p", "k2tog", "k"})), 3);
  EXPECT_EQ(max_adjacent_yarn_overs(knit(5)), 0);
  EXPECT_TRUE(adjacent_yarn_overs_ok(horseshoe_chart()));
  EXPECT_TRUE(adjacent_yarn_overs_ok(Chart{{row({"k", "yo", "yo", "sk2p", "k"})}}));
  EXPECT_FALSE(adjacent_yarn_overs_ok(Chart{{knit(4), row({"yo", "yo", "yo", "sk2p", "k2tog"})}}));

  // Repeated side by side, a row ending and starting with yarn-overs makes a longer run.
  const Row wraps = row({"yo", "k2tog", "k", "k2tog", "yo", "yo"});
  EXPECT_EQ(max_adjacent_yarn_overs(wraps), 2);
  EXPECT_EQ(max_adjacent_yarn_overs(wraps, /*repeated=*/true), 3);
  EXPECT_TRUE(adjacent_yarn_overs_ok(Chart{{wraps}}));
  EXPECT_FALSE(adjacent_yarn_overs_ok(Chart{{wraps}}, /*repeated=*/true));
}

TEST(LaceChart, WidthStaysWithinTolerance) {
  // 2 cast on -> 3 -> 2 -> 4: knittable, widths vary.
  const Chart varying{{row({"k", "yo", "k"}), row({"k", "k2tog"}), row({"yo", "k", "yo", "k"})}};
  ASSERT_TRUE(knittable(varying, 2));
  EXPECT_FALSE(width_ok(varying, 0));
  EXPECT_TRUE(width_ok(varying, 1));
  EXPECT_TRUE(width_ok(eyelet_chart(), 0));
  EXPECT_TRUE(width_ok(horseshoe_chart(), 0));
  EXPECT_THROW(width_ok(varying, -1), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::lace
