// Lace charts (Ekart 2007): symbols, the knittability and constraint checks, and the genotype
// (an ordered set of stitch trees) -- encode then decode gives the chart back, and any
// full-depth forest decodes to a chart a knitter can work.
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <string>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/stitch_tree.h"
#include "algorithms/lace/symbols.h"
#include "tests/unit/lace_test_charts.h"

namespace atelier::lace {
namespace {

using namespace test;  // row(), knit() and the charts of lace_test_charts.h

// Staggered eyelets over 8 stitches: plain rows between rows of "k2, yo, k2tog" and
// "yo, k2tog, k2", two repeats each.
Chart eyelet_chart() {
  return Chart{{knit(8), row({"k", "k", "yo", "k2tog"}, 2), knit(8), row({"yo", "k2tog", "k", "k"}, 2)}};
}

TEST(LaceSymbols, ConsumesAndNamesAreThePapers) {
  EXPECT_EQ(consumes(Symbol::k), 1);
  EXPECT_EQ(consumes(Symbol::yo), 0);
  EXPECT_EQ(consumes(Symbol::k2tog), 2);
  EXPECT_EQ(consumes(Symbol::ssk), 2);
  EXPECT_EQ(consumes(Symbol::sk2p), 3);
  for (Symbol s : kAllSymbols) EXPECT_EQ(parse_symbol(name(s)), s);
  EXPECT_EQ(name(Symbol::k2tog), "k2tog");
  EXPECT_EQ(name(Symbol::sk2p), "sk2p");
}

TEST(LaceSymbols, ParseRejectsUnknownSymbolNamingIt) {
  try {
    parse_symbol("k3tog");
    FAIL() << "k3tog accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("k3tog"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_symbol("K"), std::invalid_argument);
  EXPECT_THROW(parse_symbol(""), std::invalid_argument);
}

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

TEST(LaceStitchTree, EncodeThenDecodeIsTheIdentityOnRealCharts) {
  const struct {
    const char* name;
    Chart chart;
    int cast_on;
  } cases[] = {{"eyelet", eyelet_chart(), 8},
               {"feather and fan", feather_and_fan_chart(), 18},
               {"horseshoe", horseshoe_chart(), 10},
               {"growing", Chart{{row({"k", "yo", "k"}), row({"k", "k2tog"}), row({"yo", "k", "yo", "k"})}}, 2}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const Forest forest = encode(c.chart, c.cast_on);
    EXPECT_EQ(forest_error(forest), "");
    EXPECT_EQ(forest.trees.size(), c.chart.rows.back().size());  // one tree per last-row stitch
    EXPECT_EQ(depth(forest), static_cast<int>(c.chart.rows.size()));
    EXPECT_EQ(cast_on(forest), c.cast_on);
    EXPECT_EQ(decode(forest), c.chart);
  }
}

TEST(LaceStitchTree, TreesFollowTheStitchesBelow) {
  // Feather and fan, last row: tree 0 is a k2tog over two plain stitches, each over one cast-on
  // stitch; tree 3 is a yarn-over, a tree of one node.
  const Forest forest = encode(feather_and_fan_chart(), 18);
  const Tree& dec = forest.trees[0];
  ASSERT_EQ(dec.nodes.size(), 5u);
  EXPECT_EQ(dec.nodes[0].symbol, Symbol::k2tog);
  EXPECT_EQ(dec.nodes[dec.nodes[0].first_child].symbol, Symbol::k);
  EXPECT_EQ(dec.nodes[dec.nodes[0].first_child + 1].symbol, Symbol::k);
  int leaves = 0;
  for (const Node& n : dec.nodes) leaves += n.cast_on ? 1 : 0;
  EXPECT_EQ(leaves, 2);
  ASSERT_EQ(forest.trees[3].nodes.size(), 1u);
  EXPECT_EQ(forest.trees[3].nodes[0].symbol, Symbol::yo);

  // The paper's point: reordering the trees gives another knittable pattern.
  Forest swapped = forest;
  std::swap(swapped.trees[0], swapped.trees[3]);
  const Chart other = decode(swapped);
  EXPECT_NE(other, feather_and_fan_chart());
  EXPECT_TRUE(knittable(other, 18));
  EXPECT_EQ(other.rows[1][0], Symbol::yo);
}

TEST(LaceStitchTree, MalformedForestIsRefusedNamingTheTree) {
  // One row claimed, but tree 1 is two stitches deep.
  Forest deep;
  deep.rows = 1;
  deep.trees.push_back(Tree{{Node{false, Symbol::k, 1}, Node{true, Symbol::k, 0}}});
  deep.trees.push_back(Tree{{Node{false, Symbol::k, 1}, Node{false, Symbol::k, 2}, Node{true, Symbol::k, 0}}});
  try {
    decode(deep);
    FAIL() << "a too-deep tree was decoded";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("tree 1"), std::string::npos) << e.what();
  }
  EXPECT_EQ(depth(deep), 2);

  // A forest of yarn-overs only stands on nothing.
  Forest floating;
  floating.rows = 1;
  floating.trees.push_back(Tree{{Node{false, Symbol::yo, 0}}});
  EXPECT_NE(forest_error(floating), "");
  EXPECT_THROW(decode(floating), std::invalid_argument);
}

// Fills tree.nodes[index] with a random stitch at `row` (cast-on leaf below row 0) and grows
// its children, contiguous and after it, down to the cast-on.
void grow(Tree& tree, std::size_t index, int row, std::mt19937& rng) {
  if (row < 0) {
    tree.nodes[index] = Node{true, Symbol::k, 0};
    return;
  }
  // Mostly plain stitches, so trees stay small; every symbol appears.
  std::discrete_distribution<int> pick({5, 2, 1, 1, 1});
  const Symbol s = kAllSymbols[pick(rng)];
  const int n = consumes(s);
  const auto first = static_cast<std::uint32_t>(tree.nodes.size());
  tree.nodes[index] = Node{false, s, n > 0 ? first : 0};
  tree.nodes.resize(tree.nodes.size() + n);
  for (int c = 0; c < n; ++c) grow(tree, first + c, row - 1, rng);
}

TEST(LaceStitchTree, RandomFullDepthForestsDecodeToKnittableCharts) {
  std::mt19937 rng(20070707);
  std::uniform_int_distribution<int> rows_dist(1, 8), trees_dist(1, 14);
  for (int trial = 0; trial < 300; ++trial) {
    Forest forest;
    do {
      forest.rows = rows_dist(rng);
      forest.trees.assign(trees_dist(rng), Tree{});
      for (Tree& t : forest.trees) {
        t.nodes.resize(1);
        grow(t, 0, forest.rows - 1, rng);
      }
    } while (cast_on(forest) == 0);  // all yarn-overs: stands on no stitch, not a chart
    SCOPED_TRACE("trial " + std::to_string(trial));
    ASSERT_EQ(forest_error(forest), "");
    EXPECT_EQ(depth(forest), forest.rows);
    const Chart chart = decode(forest);
    ASSERT_EQ(static_cast<int>(chart.rows.size()), forest.rows);
    EXPECT_EQ(consumed(chart.rows[0]), cast_on(forest));
    EXPECT_EQ(produced(chart.rows.back()), static_cast<int>(forest.trees.size()));
    const Knittability k = knittable(chart, cast_on(forest));
    EXPECT_TRUE(k) << k.why;
    // Encoding the decoded chart describes the same chart again.
    EXPECT_EQ(decode(encode(chart, cast_on(forest))), chart);
  }
}

}  // namespace
}  // namespace atelier::lace
