// Lace evolution (algorithms/lace/evolve.h, Ekart 2007): fitness sharing, and every evolved
// chart is one a knitter can work and that satisfies the paper's constraints, reproducibly.
#include <gtest/gtest.h>

#include <atomic>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/evolve.h"
#include "algorithms/lace/fitness.h"
#include "algorithms/lace/stitch_tree.h"
#include "algorithms/lace/symbols.h"
#include "tests/support/lace_test_charts.h"

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
      // (hole_lines rewards lace too, and the yarn-over band caps what the holes weight can do.)
      if (only_knit_length) {
        p.weights.symmetry = p.weights.depth = p.weights.hole_lines = 0;
        p.weights.yo_band = p.weights.width_change = 0;
      }
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
    return count(c, Symbol::sk2p) + count(c, Symbol::s2kp);
  };
  const EvolveResult r = evolve(p);
  EXPECT_EQ(count(r.chart, Symbol::sk2p) + count(r.chart, Symbol::s2kp), 0);
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

TEST(LaceEvolve, StagnationStopsTheRun) {
  EvolveParams p = small_params(3);
  p.generations = 2000;
  p.stagnation = 5;
  const EvolveResult r = evolve(p);
  EXPECT_EQ(r.stopped_by, "stagnation");
  EXPECT_LT(r.generations_run, p.generations);
  EXPECT_GE(r.generations_run, p.stagnation);
  EXPECT_EQ(static_cast<int>(r.best_score.size()), r.generations_run + 1);
  EXPECT_TRUE(r.evaluation.constraints.ok());
}

TEST(LaceEvolve, TargetScoreStopsWhenGoodEnough) {
  EvolveParams p = small_params(4);
  p.generations = 500;
  p.target_score = -1e6;  // any feasible chart is good enough: generation 0 has one
  EvolveResult r = evolve(p);
  EXPECT_EQ(r.stopped_by, "target_score");
  EXPECT_EQ(r.generations_run, 0);
  p.target_score = 1e6;  // never reached: the bound stops it
  p.generations = 10;
  r = evolve(p);
  EXPECT_EQ(r.stopped_by, "generations");
  EXPECT_EQ(r.generations_run, 10);
  p.target_score = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(evolve(p), std::invalid_argument);
}

TEST(LaceEvolve, DesignWeightsAreValidated) {
  EvolveParams p = small_params(1);
  p.weights.hole_lines = -1;
  EXPECT_THROW(evolve(p), std::invalid_argument);
  p = small_params(1);
  p.weights.yo_band = std::numeric_limits<double>::infinity();
  EXPECT_THROW(evolve(p), std::invalid_argument);
  p = small_params(1);
  p.weights.yo_share_min = 0.3;  // above the band's top
  EXPECT_THROW(evolve(p), std::invalid_argument);
}

// What a designed chart clears and a random mesh does not (hole_lines_test.cc: meshes at
// lace density score 0.1-0.6 on hole_lines and 0.0-0.15 on symmetry).
constexpr double kHoleLinesFloor = 0.8, kSymmetryFloor = 0.6;

// The converter's defaults (lace_params.h): 12 x 16, population 500, up to 200 generations,
// stop after 100 without a better chart.
EvolveParams default_params(std::uint64_t seed) {
  EvolveParams p;
  p.seed = seed;
  p.stagnation = 100;
  return p;
}

TEST(LaceEvolve, DefaultChartsReadAsADesign) {
  for (std::uint64_t seed : {1, 2, 3}) {
    const EvolveResult r = evolve(default_params(seed));
    const Objectives& o = r.evaluation.objectives;
    EXPECT_TRUE(r.evaluation.constraints.ok());
    EXPECT_GE(o.yo_share, 0.10) << seed;
    EXPECT_LE(o.yo_share, 0.25) << seed;
    EXPECT_GE(o.hole_lines, kHoleLinesFloor) << seed;
    EXPECT_GE(o.symmetry, kSymmetryFloor) << seed;
  }
}

TEST(LaceEvolve, TheOldWeightsGiveARandomMesh) {
  // Before issue 22: holes, knit_length, depth and symmetry 0.5 only, no band, no lines.
  EvolveParams p = default_params(1);
  p.stagnation = 0;
  p.weights.symmetry = 0.5;
  p.weights.hole_lines = p.weights.yo_band = p.weights.width_change = 0;
  const EvolveResult r = evolve(p);
  // ~40 % holes: outside classic lace's band, the design check fails. (The new symmetric seeds
  // and mirror mutation make even these charts symmetric; with main's operators seeds 1-3 had
  // symmetry 0.37-0.44 and 70-84 % of the holes in lines at 41-42 % holes.)
  EXPECT_GT(r.evaluation.objectives.yo_share, 0.25);
}

}  // namespace
}  // namespace atelier::lace
