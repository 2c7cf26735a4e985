// Lace genetic programming (Ekart 2007, sections 4-7): the fitness terms on hand-drawn charts,
// the operators keep the trees well-formed, and every evolved chart is one a knitter can work
// and that satisfies the paper's constraints, reproducibly.
#include <gtest/gtest.h>

#include <atomic>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/evolve.h"
#include "algorithms/lace/fitness.h"
#include "algorithms/lace/operators.h"
#include "algorithms/lace/random_chart.h"
#include "algorithms/lace/stitch_tree.h"
#include "algorithms/lace/symbols.h"
#include "tests/unit/lace_test_charts.h"

namespace atelier::lace {
namespace {

using namespace test;  // row(), knit() and the charts of lace_test_charts.h

int count(const Chart& chart, Symbol s) {
  int n = 0;
  for (const Row& r : chart.rows) {
    for (Symbol x : r) n += x == s ? 1 : 0;
  }
  return n;
}

EvolveParams small_params(std::uint64_t seed) {
  EvolveParams p;
  p.width = 8;
  p.rows = 8;
  p.population = 60;
  p.generations = 25;
  p.seed = seed;
  return p;
}

TEST(LaceFitness, AllPlainChartHasNoHolesAndFullKnitLength) {
  const Chart plain{{knit(6), knit(6), knit(6), knit(6)}};
  const Evaluation e = evaluate(plain, 6, Weights{}, 2);
  EXPECT_TRUE(e.constraints.ok());
  EXPECT_DOUBLE_EQ(e.objectives.holes, 0.0);
  EXPECT_DOUBLE_EQ(e.objectives.knit_length, 1.0);
  EXPECT_DOUBLE_EQ(e.objectives.depth, 0.0);
  // No motif, so no symmetry to reward: plain knitting must not win on a trivial mirror.
  EXPECT_DOUBLE_EQ(e.objectives.symmetry, 0.0);
  // Eq. 2 with the default weights: 0.5 * knit_length.
  EXPECT_DOUBLE_EQ(e.score, 0.5);
}

TEST(LaceFitness, ThreeYarnOversSideBySideIsOneExcess) {
  // 7 cast on: "k, yo, yo, yo, sk2p, k2tog, k" -- balanced, but three yarn-overs together.
  const Chart chart{{row({"k", "yo", "yo", "yo", "sk2p", "k2tog", "k"})}};
  ASSERT_TRUE(knittable(chart, 7));
  const Evaluation e = evaluate(chart, 7, Weights{}, 2);
  EXPECT_EQ(e.constraints.adjacent_yo_excess, 1);
  EXPECT_EQ(e.constraints.balance_error, 0);
  EXPECT_FALSE(e.constraints.ok());
  EXPECT_LT(e.score, 0.0);  // worse than any feasible chart (whose score is >= 0)

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

TEST(LaceSharing, IdenticalCopiesShareOneNiche) {
  const ChartSignature s = signature(horseshoe_chart(), 12);
  const std::vector<ChartSignature> same(37, s);
  for (int threads : {1, 2, 3}) {
    const std::vector<double> m = niche_counts(same, 6.0, 1.0, threads);
    ASSERT_EQ(m.size(), 37u);
    for (double v : m) EXPECT_DOUBLE_EQ(v, 37.0);
  }
  // Charts 3 cells apart share 1 - 3/6 of a niche of radius 6.
  Chart other = horseshoe_chart();
  for (int j = 0; j < 3; ++j) other.rows[0][j + 1] = Symbol::ssk;
  const ChartSignature o = signature(other, 12);
  EXPECT_EQ(distance(s, o), 3);
  const std::vector<double> m = niche_counts({s, o}, 6.0, 1.0, 2);
  EXPECT_DOUBLE_EQ(m[0], 1.5);
  EXPECT_DOUBLE_EQ(m[1], 1.5);
  EXPECT_DOUBLE_EQ(niche_counts({s, o}, 0.0, 1.0, 2)[0], 1.0);
}

TEST(LaceEvolve, EveryEvolvedChartIsKnittableAndFeasible) {
  std::set<std::vector<Row>> distinct;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    EvolveParams p = small_params(seed);
    int reported = 0;
    p.progress = [&](int g, int total) {
      EXPECT_EQ(g, reported + 1);
      EXPECT_EQ(total, p.generations);
      reported = g;
    };
    const EvolveResult r = evolve(p);
    EXPECT_EQ(r.cast_on, p.width);
    ASSERT_TRUE(knittable(r.chart, r.cast_on)) << "seed " << seed << ": " << knittable(r.chart, r.cast_on).why;
    EXPECT_EQ(static_cast<int>(r.chart.rows.size()), p.rows);
    EXPECT_EQ(produced(r.chart.rows.back()), p.width);
    EXPECT_TRUE(yarn_over_balance(r.chart)) << "seed " << seed;
    EXPECT_TRUE(adjacent_yarn_overs_ok(r.chart, /*repeated=*/true)) << "seed " << seed;
    EXPECT_TRUE(width_ok(r.chart, p.width_tolerance)) << "seed " << seed;
    EXPECT_TRUE(r.evaluation.constraints.ok());
    const Evaluation again = evaluate(r.chart, r.cast_on, p.weights, p.width_tolerance);
    EXPECT_DOUBLE_EQ(again.score, r.evaluation.score);
    EXPECT_EQ(r.generations_run, p.generations);
    EXPECT_EQ(reported, p.generations);
    ASSERT_EQ(static_cast<int>(r.best_score.size()), p.generations + 1);
    EXPECT_GE(r.best_score.back(), r.evaluation.score);  // elitism keeps the best
    EXPECT_GT(r.feasible_in_final_population, 0);
    distinct.insert(r.chart.rows);
  }
  EXPECT_GT(distinct.size(), 10u) << "different seeds should give different charts";
}

TEST(LaceEvolve, SameSeedSameChartWhateverTheThreads) {
  EvolveParams p = small_params(42);
  p.threads = 1;
  const EvolveResult one = evolve(p);
  p.threads = 2;
  const EvolveResult two = evolve(p);
  p.threads = 3;
  const EvolveResult three = evolve(p);
  EXPECT_EQ(one.chart, two.chart);
  EXPECT_EQ(one.chart, three.chart);
  EXPECT_EQ(one.best_score, two.best_score);
  EXPECT_EQ(one.best_score, three.best_score);
  p.seed = 43;
  EXPECT_NE(evolve(p).chart, one.chart);
}

TEST(LaceEvolve, HolesWeightGivesMoreHoles) {
  // Holes against plain runs alone (symmetry and depth also reward lace, which would blur
  // what the holes weight does), and with every default weight.
  for (const bool only_knit_length : {true, false}) {
    int few = 0, many = 0;
    for (std::uint64_t seed = 1; seed <= 4; ++seed) {
      EvolveParams p = small_params(seed);
      p.generations = 40;
      if (only_knit_length) p.weights.symmetry = p.weights.depth = 0;
      p.weights.holes = 0;
      few += count(evolve(p).chart, Symbol::yo);
      p.weights.holes = 5;
      many += count(evolve(p).chart, Symbol::yo);
    }
    if (only_knit_length) {
      EXPECT_GT(2 * many, 3 * few) << "holes weight 5: " << many << " yarn-overs, weight 0: " << few;
    } else {
      EXPECT_GT(many, few) << "holes weight 5: " << many << " yarn-overs, weight 0: " << few;
    }
  }
}

TEST(LaceEvolve, StartChartWithNoGenerationsComesBack) {
  EvolveParams p;
  p.start = horseshoe_chart();
  p.start_cast_on = 10;
  p.generations = 0;
  p.population = 20;
  const EvolveResult r = evolve(p);
  EXPECT_EQ(r.chart, horseshoe_chart());
  EXPECT_EQ(r.cast_on, 10);
  EXPECT_EQ(r.generations_run, 0);

  // With generations, variations of it: still 10 wide, 4 rows, feasible, at least as good.
  p.generations = 10;
  const EvolveResult v = evolve(p);
  EXPECT_EQ(v.cast_on, 10);
  EXPECT_EQ(v.chart.rows.size(), 4u);
  EXPECT_TRUE(knittable(v.chart, 10));
  EXPECT_TRUE(v.evaluation.constraints.ok());
  EXPECT_GE(v.evaluation.score, r.evaluation.score);
}

TEST(LaceEvolve, ExtraViolationsAreConstraints) {
  // A caller that forbids double decreases (e.g. a machine that cannot do them) never gets one.
  EvolveParams p = small_params(9);
  std::atomic<int> calls{0};
  p.extra_violations = [&](const Chart& c, int cast_on) {
    EXPECT_EQ(cast_on, 8);
    ++calls;
    return count(c, Symbol::sk2p);
  };
  const EvolveResult r = evolve(p);
  EXPECT_EQ(count(r.chart, Symbol::sk2p), 0);
  EXPECT_EQ(r.evaluation.constraints.extra, 0);
  EXPECT_GT(calls.load(), p.population);
  // Nothing can satisfy it: a clear error, not an infeasible chart.
  p.extra_violations = [](const Chart&, int) { return 1; };
  EXPECT_THROW(evolve(p), std::runtime_error);
}

TEST(LaceEvolve, BadParametersAreRefusedNamingTheField) {
  auto refused = [](EvolveParams p, const std::string& field) {
    try {
      evolve(p);
      ADD_FAILURE() << field << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  EvolveParams p = small_params(1);
  p.width = 1;
  refused(p, "width");
  p = small_params(1);
  p.rows = 0;
  refused(p, "rows");
  p = small_params(1);
  p.population = 1;
  refused(p, "population");
  p = small_params(1);
  p.weights.holes = -1;
  refused(p, "weights.holes");
  p = small_params(1);
  p.generations = -1;
  refused(p, "generations");
  p = small_params(1);
  p.elites = p.population;
  refused(p, "elites");
  p = small_params(1);
  p.start = Chart{{row({"k", "yo", "k"})}};  // ends wider than its cast-on of 2
  p.start_cast_on = 2;
  refused(p, "start");
}

}  // namespace
}  // namespace atelier::lace
