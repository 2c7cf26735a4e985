// The lace genetic operators (algorithms/lace/operators.h): every operator keeps the trees
// well-formed; flip-slant and lengthen-plain-run do what they say.
#include <gtest/gtest.h>

#include <random>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/fitness.h"
#include "algorithms/lace/operators.h"
#include "algorithms/lace/random_chart.h"
#include "algorithms/lace/stitch_tree.h"
#include "algorithms/lace/symbols.h"
#include "tests/support/lace_test_charts.h"

namespace atelier::lace {
namespace {

using namespace test;  // row(), knit() and the charts of lace_test_charts.h

TEST(LaceOperators, EveryOperatorKeepsForestsWellFormed) {
  std::mt19937_64 rng(11);
  const char* names[] = {"crossover", "subtree_mutation", "flip_slant", "lengthen_plain_run",
                         "swap_trees"};
  int applied[5] = {};
  Chart fast;
  for (int i = 0; i < 400; ++i) {
    const int width = 2 + i % 11, rows = 1 + i % 10;
    Forest a = i % 2 ? random_forest(width, rows, rng)
                     : encode(random_feasible_chart(width, rows, rng), width);
    const Forest b = random_forest(width, rows, rng);
    for (int step = 0; step < 5; ++step) {
      const int op = (i + step) % 5;
      bool changed = false;
      switch (op) {
        case 0: changed = crossover(a, b, rng); break;
        case 1: changed = subtree_mutation(a, rng); break;
        case 2: changed = flip_slant(a, rng); break;
        case 3: changed = lengthen_plain_run(a, rng); break;
        case 4: changed = swap_trees(a, rng); break;
      }
      applied[op] += changed ? 1 : 0;
      ASSERT_EQ(forest_error(a), "") << names[op] << " at case " << i;
      ASSERT_EQ(a.rows, rows);
      ASSERT_EQ(static_cast<int>(a.trees.size()), width);
      decode_into(a, fast);
      ASSERT_EQ(fast, decode(a)) << names[op];
      ASSERT_TRUE(knittable(fast, cast_on(a)));
    }
  }
  for (int op = 0; op < 5; ++op) EXPECT_GT(applied[op], 50) << names[op] << " hardly ever applied";
}

TEST(LaceOperators, FlipSlantFlipsExactlyOneDecrease) {
  const Chart mirror{{knit(7), row({"k", "yo", "ssk", "k", "k2tog", "yo", "k"})}};
  std::mt19937_64 rng(3);
  for (int i = 0; i < 20; ++i) {
    Forest f = encode(mirror, 7);
    ASSERT_TRUE(flip_slant(f, rng));
    const Chart c = decode(f);
    int differ = 0;
    for (std::size_t r = 0; r < c.rows.size(); ++r) {
      for (std::size_t j = 0; j < c.rows[r].size(); ++j) {
        if (c.rows[r][j] != mirror.rows[r][j]) {
          ++differ;
          const Symbol was = mirror.rows[r][j], now = c.rows[r][j];
          EXPECT_TRUE((was == Symbol::ssk && now == Symbol::k2tog) ||
                      (was == Symbol::k2tog && now == Symbol::ssk));
        }
      }
    }
    EXPECT_EQ(differ, 1);
  }
  Forest plain = encode(Chart{{knit(4)}}, 4);
  EXPECT_FALSE(flip_slant(plain, rng));
  EXPECT_EQ(decode(plain), (Chart{{knit(4)}}));
}

TEST(LaceOperators, LengthenPlainRunGrowsARunByOneRow) {
  // 4 stitches: row 0 "k2tog, yo, k, k", row 1 plain. The k of row 1 over the k2tog becomes a
  // run of two rows; the chart loses the k2tog's other stitch, so it starts one narrower.
  const Chart chart{{row({"k2tog", "yo", "k", "k"}), knit(4)}};
  std::mt19937_64 rng(5);
  Forest f = encode(chart, 4);
  ASSERT_TRUE(lengthen_plain_run(f, rng));
  const Chart c = decode(f);
  EXPECT_EQ(c.rows[1], knit(4));
  EXPECT_EQ(c.rows[0], row({"k", "yo", "k", "k"}));
  EXPECT_EQ(cast_on(f), 3);
  EXPECT_GT(evaluate(c, 3, Weights{}, 2).objectives.knit_length,
            evaluate(chart, 4, Weights{}, 2).objectives.knit_length);
  Forest none = encode(Chart{{knit(3), knit(3)}}, 3);
  EXPECT_FALSE(lengthen_plain_run(none, rng));
}

// Row r read as in a mirror: reversed, k2tog <-> ssk.
Row mirror_row(const Row& row) {
  Row out(row.rbegin(), row.rend());
  for (Symbol& s : out) s = mirrored_symbol(s);
  return out;
}

TEST(LaceOperators, NewMutationsKeepForestsWellFormedAndKnittable) {
  std::mt19937_64 rng(23);
  int applied[3] = {};
  for (int i = 0; i < 400; ++i) {
    const int width = 2 + i % 11, rows = 1 + i % 10;
    Forest f = i % 2 ? random_forest(width, rows, rng) : encode(random_feasible_chart(width, rows, rng), width);
    for (int step = 0; step < 6; ++step) {
      const int op = (i + step) % 3;
      bool changed = false;
      switch (op) {
        case 0: changed = shorten_plain_run(f, rng); break;
        case 1: changed = point_mutation(f, rng); break;
        case 2: changed = mirror_tree(f, rng); break;
      }
      applied[op] += changed ? 1 : 0;
      ASSERT_EQ(forest_error(f), "") << "op " << op << " forest " << i;
      ASSERT_EQ(f.rows, rows);
      ASSERT_EQ(static_cast<int>(f.trees.size()), width);
      const Chart c = decode(f);
      ASSERT_TRUE(knittable(c, cast_on(f))) << "op " << op << " forest " << i;
      Chart fast;
      decode_into(f, fast);
      ASSERT_EQ(fast, c);
    }
  }
  for (int n : applied) EXPECT_GT(n, 100);
}

TEST(LaceOperators, ShortenPlainRunCutsARunOfPlainStitches) {
  std::mt19937_64 rng(5);
  // Two rows: the only k on a k is row 1's over row 0's, so the new decrease stands on the
  // cast-on (no random tree comes with it) and is the chart's only one.
  const Chart plain{{knit(6), knit(6)}};
  for (int trial = 0; trial < 20; ++trial) {
    Forest f = encode(plain, 6);
    ASSERT_TRUE(shorten_plain_run(f, rng));
    const Chart c = decode(f);
    int decreases = 0;
    for (const Row& r : c.rows) {
      for (Symbol s : r) decreases += s == Symbol::k2tog || s == Symbol::ssk ? 1 : 0;
    }
    EXPECT_EQ(decreases, 1);
    // A column of plain knitting is broken: knit length falls below the all-plain 1.
    EXPECT_LT(evaluate(c, cast_on(f), Weights{}, 50).objectives.knit_length, 1.0);
  }
  // A single row has no k standing on a k.
  Forest one = encode(Chart{{knit(4)}}, 4);
  EXPECT_FALSE(shorten_plain_run(one, rng));
}

TEST(LaceOperators, PointMutationKeepsAFeasibleChartFeasible) {
  std::mt19937_64 rng(9);
  int changed = 0;
  for (int i = 0; i < 200; ++i) {
    const Chart chart = random_feasible_chart(12, 8, rng);
    Forest f = encode(chart, 12);
    if (!point_mutation(f, rng)) continue;
    ++changed;
    const Chart c = decode(f);
    EXPECT_EQ(cast_on(f), 12);
    EXPECT_NE(c, chart);
    EXPECT_TRUE(evaluate(c, 12, Weights{}, 0).constraints.ok());
    for (std::size_t r = 0; r < c.rows.size(); ++r) {
      ASSERT_EQ(c.rows[r].size(), chart.rows[r].size());
      int differ = 0;
      for (std::size_t j = 0; j < c.rows[r].size(); ++j) {
        if (c.rows[r][j] != chart.rows[r][j]) {
          ++differ;
          EXPECT_EQ(consumes(c.rows[r][j]), consumes(chart.rows[r][j]));
        }
      }
      EXPECT_LE(differ, 1);
    }
  }
  EXPECT_GT(changed, 150);
  Forest plain = encode(Chart{{knit(4), knit(4)}}, 4);
  EXPECT_FALSE(point_mutation(plain, rng));  // k and yo have no same-arity partner
}

TEST(LaceOperators, MirrorTreeMakesTheRowsSymmetric) {
  std::mt19937_64 rng(13);
  for (int width : {7, 12}) {
    Forest f = encode(random_feasible_chart(width, 6, rng), width);
    bool symmetric = false;
    for (int call = 0; call < 30 && !symmetric; ++call) {
      if (!mirror_tree(f, rng)) continue;
      ASSERT_EQ(forest_error(f), "");
      const Chart c = decode(f);
      symmetric = true;
      for (std::size_t r = 0; r < c.rows.size(); ++r) {
        // The odd middle tree is not mirrored onto itself: compare without it.
        Row row = c.rows[r], mirror = mirror_row(c.rows[r]);
        symmetric = symmetric && (row == mirror || width % 2 == 1);
      }
      if (width % 2 == 1) symmetric = symmetric && evaluate(c, cast_on(f), Weights{}, 50).objectives.symmetry > 0.5;
    }
    EXPECT_TRUE(symmetric) << width;
  }
  Forest one = encode(Chart{{knit(1)}}, 1);
  EXPECT_FALSE(mirror_tree(one, rng));
}

}  // namespace
}  // namespace atelier::lace
