// The lace genotype (algorithms/lace/stitch_tree.h): encode then decode gives the chart back,
// and any full-depth forest decodes to a chart a knitter can work.
#include <gtest/gtest.h>

#include <random>
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
