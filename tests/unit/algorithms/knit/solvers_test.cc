// The local-search solvers of the float constraint (algorithms/knit/solvers.h): no violations
// left, fewest flips, reproducible seeds, progress and cancel.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <stdexcept>
#include <vector>

#include "algorithms/knit/dither.h"
#include "algorithms/knit/floats.h"
#include "algorithms/knit/solvers.h"
#include "algorithms/knit/stitch_grid.h"
#include "tests/support/knit_test_images.h"

namespace atelier::knit {
namespace {

const Solver kComplete[] = {Solver::min_conflict, Solver::gsat, Solver::hybrid, Solver::texturing,
                            Solver::hybrid_texturing};

// Random 0/1 grid where each stitch repeats its left neighbour with probability `stick`
// (high stick = long runs, as in flat areas of a picture).
cv::Mat random_grid(int rows, int cols, double stick, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::bernoulli_distribution same(stick), coin(0.5);
  cv::Mat g(rows, cols, CV_8UC1);
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < cols; ++x)
      g.at<uint8_t>(y, x) = x > 0 && same(rng) ? g.at<uint8_t>(y, x - 1) : coin(rng);
  return g;
}

cv::Mat relax_block(cv::Size size) {
  cv::Mat m(size, CV_8UC1, cv::Scalar(0));
  m(cv::Rect(size.width / 4, size.height / 3, size.width / 3, size.height / 3)).setTo(1);
  return m;
}

// Sum over violating runs of floor(L / (f + 1)): the fewest flips that can repair the grid
// (each flip shortens only the run it lies in).
long minimum_flips(const cv::Mat& grid, const FloatRules& rules) {
  long total = 0;
  for (const auto& run : violating_runs(grid, rules)) total += run.length / (rules.max_float + 1);
  return total;
}

cv::Mat real_grid(const std::string& name, int width, Dither d) {
  const cv::Mat gray = to_stitch_grid(testing::load_test_image(name), GaugeParams{width, 28, 36});
  return dither(gray, d);
}

void expect_solved(const cv::Mat& before, const cv::Mat& after, const FloatRules& rules,
                   const SolveStats& stats, const std::string& what) {
  EXPECT_EQ(count_violations(after, rules), 0) << what;
  EXPECT_EQ(stats.violations_after, 0) << what;
  EXPECT_TRUE(stats.complete) << what;
  EXPECT_LE(longest_float(after, rules), rules.max_float) << what;
  EXPECT_EQ(stats.violations_before, count_violations(before, rules)) << what;
  const int changed = cv::countNonZero(before != after);
  EXPECT_LE(changed, stats.flips) << what;
  EXPECT_EQ(stats.flips, stats.random_walk_flips + stats.search_flips) << what;
  if (!rules.relax.empty()) {
    cv::Mat changed_relaxed = (before != after) & (rules.relax != 0);
    EXPECT_EQ(cv::countNonZero(changed_relaxed), 0) << what << ": a relaxed stitch was flipped";
  }
}

TEST(KnitSolvers, CompleteSolversLeaveNoViolationsOnRandomGrids) {
  for (int f : {2, 3, 4, 6}) {
    for (bool anchoring : {true, false}) {
      for (bool relaxed : {false, true}) {
        for (double stick : {0.5, 0.85, 0.95}) {
          const cv::Mat start = random_grid(23, 61, stick, 7 + f);
          FloatRules rules;
          rules.max_float = f;
          rules.anchoring = anchoring;
          if (relaxed) rules.relax = relax_block(start.size());
          ASSERT_GT(count_violations(start, rules), 0);
          for (Solver s : kComplete) {
            cv::Mat grid = start.clone();
            SolverParams params;
            params.solver = s;
            params.seed = 99;
            const SolveStats stats = solve(grid, rules, params);
            expect_solved(start, grid, rules, stats,
                          solver_name(s) + " f=" + std::to_string(f) + " anchoring=" +
                              std::to_string(anchoring) + " relaxed=" + std::to_string(relaxed) +
                              " stick=" + std::to_string(stick));
          }
        }
      }
    }
  }
}

TEST(KnitSolvers, CompleteSolversLeaveNoViolationsOnRealImages) {
  for (const char* name : {"starry_night.jpg", "pic1.png", "LinuxLogo.jpg", "fruits.jpg"}) {
    for (Dither d : {Dither::floyd_steinberg, Dither::threshold, Dither::ordered}) {
      const cv::Mat start = real_grid(name, 150, d);
      for (int f : {2, 4}) {
        for (bool anchoring : {true, false}) {
          FloatRules rules;
          rules.max_float = f;
          rules.anchoring = anchoring;
          rules.relax = relax_block(start.size());
          for (Solver s : kComplete) {
            cv::Mat grid = start.clone();
            SolverParams params;
            params.solver = s;
            const SolveStats stats = solve(grid, rules, params);
            expect_solved(start, grid, rules, stats,
                          std::string(name) + " " + dither_name(d) + " " + solver_name(s) +
                              " f=" + std::to_string(f) + " anchoring=" + std::to_string(anchoring));
          }
        }
      }
    }
  }
}

TEST(KnitSolvers, GsatBreaksAnIsolatedRunWithTheFewestFlips) {
  for (int f = 2; f <= 6; ++f) {
    for (int length = 5; length <= 40; ++length) {
      if (length <= f) continue;
      // Alternating background, then `length` ones starting after a 0, then alternating on.
      const int lead = 10, cols = lead + length + 10;
      cv::Mat grid(1, cols, CV_8UC1);
      for (int x = 0; x < cols; ++x)
        grid.at<uint8_t>(0, x) = (x >= lead && x < lead + length) ? 1 : (x % 2);
      grid.at<uint8_t>(0, lead - 1) = 0;
      grid.at<uint8_t>(0, lead + length) = 0;
      FloatRules rules;
      rules.max_float = f;
      ASSERT_EQ(count_violations(grid, rules), length - f);
      for (uint64_t seed : {1, 2, 3}) {
        cv::Mat g = grid.clone();
        SolverParams params;
        params.solver = Solver::gsat;
        params.seed = seed;
        const SolveStats stats = solve(g, rules, params);
        EXPECT_EQ(stats.flips, length / (f + 1)) << "L=" << length << " f=" << f;
        EXPECT_EQ(count_violations(g, rules), 0) << "L=" << length << " f=" << f;
      }
    }
  }
}

TEST(KnitSolvers, GsatFlipsTheMinimumOnWholeGrids) {
  for (int f : {2, 3, 4, 6}) {
    for (bool anchoring : {true, false}) {
      FloatRules rules;
      rules.max_float = f;
      rules.anchoring = anchoring;
      rules.relax = relax_block(cv::Size(80, 30));
      const cv::Mat start = random_grid(30, 80, 0.8, 3 * f + anchoring);
      cv::Mat grid = start.clone();
      SolverParams params;
      params.solver = Solver::gsat;
      const SolveStats gsat = solve(grid, rules, params);
      EXPECT_EQ(gsat.flips, minimum_flips(start, rules)) << "f=" << f;
      EXPECT_EQ(cv::countNonZero(start != grid), gsat.flips) << "a stitch was flipped twice";
      for (Solver other : {Solver::min_conflict, Solver::texturing, Solver::hybrid}) {
        cv::Mat g = start.clone();
        params.solver = other;
        EXPECT_GE(solve(g, rules, params).flips, gsat.flips) << solver_name(other);
      }
    }
  }
}

TEST(KnitSolvers, RandomWalkFlipsOnlyWhenItRepairsAtLeastM) {
  const cv::Mat start = real_grid("starry_night.jpg", 200, Dither::threshold);
  FloatRules rules;
  cv::Mat grid = start.clone();
  SolverParams params;
  params.solver = Solver::random_walk;
  const SolveStats stats = solve(grid, rules, params);
  EXPECT_GT(stats.random_walk_flips, 0);
  EXPECT_EQ(stats.search_flips, 0);
  EXPECT_LT(stats.violations_after, stats.violations_before);
  EXPECT_GE(stats.violations_before - stats.violations_after, params.rw_m * stats.flips);
  // With m above the best a single flip can repair (f+1), Random Walk never flips.
  grid = start.clone();
  params.rw_m = rules.max_float + 2;
  EXPECT_EQ(solve(grid, rules, params).flips, 0);
  EXPECT_EQ(cv::countNonZero(grid != start), 0);
}

TEST(KnitSolvers, HybridRunsRandomWalkThenGsat) {
  const cv::Mat start = real_grid("starry_night.jpg", 200, Dither::threshold);
  FloatRules rules;
  cv::Mat grid = start.clone();
  SolverParams params;
  params.solver = Solver::hybrid;
  const SolveStats stats = solve(grid, rules, params);
  EXPECT_GT(stats.random_walk_flips, 0);
  EXPECT_GT(stats.search_flips, 0);
  EXPECT_TRUE(stats.complete);
  // m = 2f+1 is out of reach for one flip: the hybrid reduces to GSAT (paper 4.4).
  cv::Mat a = start.clone(), b = start.clone();
  params.rw_m = 2 * rules.max_float + 1;
  const SolveStats h = solve(a, rules, params);
  params.solver = Solver::gsat;
  const SolveStats g = solve(b, rules, params);
  EXPECT_EQ(h.random_walk_flips, 0);
  EXPECT_EQ(h.flips, g.flips);
}

// The share of rows whose flips fall in the most used column: how much the second phase's
// breaks line up into vertical stripes on a picture made of identical rows.
double column_alignment(const cv::Mat& before, const cv::Mat& after) {
  std::vector<int> per_column(before.cols, 0);
  for (int y = 0; y < before.rows; ++y)
    for (int x = 0; x < before.cols; ++x)
      if (before.at<uint8_t>(y, x) != after.at<uint8_t>(y, x)) ++per_column[x];
  return static_cast<double>(*std::max_element(per_column.begin(), per_column.end())) / before.rows;
}

// The paper's second hybrid (4.4-4.5): the same Random Walk first, then pseudo-random
// texturing instead of GSAT: more flips than GSAT's minimum but breaks that do not line up.
TEST(KnitSolvers, HybridTexturingRunsRandomWalkThenTexturing) {
  const cv::Mat start = real_grid("starry_night.jpg", 200, Dither::threshold);
  FloatRules rules;
  SolverParams params;
  cv::Mat walk = start.clone(), gsat_hybrid = start.clone(), tex_hybrid = start.clone();
  params.solver = Solver::random_walk;
  const SolveStats w = solve(walk, rules, params);
  params.solver = Solver::hybrid;
  const SolveStats h = solve(gsat_hybrid, rules, params);
  params.solver = Solver::hybrid_texturing;
  const SolveStats t = solve(tex_hybrid, rules, params);
  expect_solved(start, tex_hybrid, rules, t, "hybrid-texturing");
  // Same seed, same first phase as Random Walk alone and as the GSAT hybrid.
  EXPECT_GT(t.random_walk_flips, 0);
  EXPECT_EQ(t.random_walk_flips, w.random_walk_flips);
  EXPECT_EQ(t.random_walk_flips, h.random_walk_flips);
  // Texturing breaks every f stitches: more than GSAT's minimum on what the walk left.
  EXPECT_EQ(h.search_flips, minimum_flips(walk, rules));
  EXPECT_GT(t.search_flips, h.search_flips);
  EXPECT_GT(cv::countNonZero(tex_hybrid != gsat_hybrid), 0);

  // A block of identical dark rows (a vertical structure): GSAT's breaks sit f + 1 from
  // either end, so they stack up in columns; texturing's random shift spreads them.
  cv::Mat block(400, 60, CV_8UC1, cv::Scalar(0));
  block(cv::Rect(10, 0, 41, block.rows)).setTo(1);
  params.rw_m = 2 * rules.max_float + 1;  // no walk: compare the second phases alone
  cv::Mat by_gsat = block.clone(), by_texturing = block.clone();
  params.solver = Solver::hybrid;
  solve(by_gsat, rules, params);
  params.solver = Solver::hybrid_texturing;
  const SolveStats reduced = solve(by_texturing, rules, params);
  EXPECT_EQ(reduced.random_walk_flips, 0);  // m = 2f+1 reduces it to texturing
  EXPECT_TRUE(reduced.complete);
  const double a_gsat = column_alignment(block, by_gsat);
  const double a_tex = column_alignment(block, by_texturing);
  EXPECT_LT(a_tex, a_gsat) << "texturing " << a_tex << " vs GSAT " << a_gsat;
  EXPECT_LT(a_tex, 0.45);
}

// The auto search solves both hybrids from one walk: the same grids and counts as solve().
TEST(KnitSolvers, SolveHybridsEqualsSolvingEachHybrid) {
  const cv::Mat start = real_grid("fruits.jpg", 150, Dither::floyd_steinberg);
  FloatRules rules;
  SolverParams params;
  params.seed = 9;
  cv::Mat a = start.clone(), b = start.clone(), ga, tb;
  params.solver = Solver::hybrid;
  const SolveStats sa = solve(a, rules, params);
  params.solver = Solver::hybrid_texturing;
  const SolveStats sb = solve(b, rules, params);
  SolveStats sga, stb;
  solve_hybrids(start, rules, params, ga, sga, tb, stb);
  EXPECT_EQ(cv::countNonZero(a != ga), 0);
  EXPECT_EQ(cv::countNonZero(b != tb), 0);
  EXPECT_EQ(sa.flips, sga.flips);
  EXPECT_EQ(sa.random_walk_flips, sga.random_walk_flips);
  EXPECT_EQ(sb.search_flips, stb.search_flips);
  EXPECT_EQ(sb.violations_before, stb.violations_before);
  EXPECT_TRUE(sga.complete && stb.complete);
}

TEST(KnitSolvers, SameSeedSameGridDifferentSeedDifferentGrid) {
  const cv::Mat start = real_grid("starry_night.jpg", 120, Dither::floyd_steinberg);
  FloatRules rules;
  for (Solver s : {Solver::random_walk, Solver::hybrid, Solver::texturing, Solver::min_conflict,
                   Solver::gsat, Solver::hybrid_texturing}) {
    SolverParams params;
    params.solver = s;
    params.seed = 5;
    cv::Mat a = start.clone(), b = start.clone(), c = start.clone();
    solve(a, rules, params);
    solve(b, rules, params);
    params.seed = 6;
    solve(c, rules, params);
    EXPECT_EQ(cv::countNonZero(a != b), 0) << solver_name(s) << " is not reproducible";
    EXPECT_GT(cv::countNonZero(a != c), 0) << solver_name(s) << " ignores the seed";
  }
}

TEST(KnitSolvers, ProgressIsReportedAndMayCancel) {
  const cv::Mat start = real_grid("fruits.jpg", 300, Dither::floyd_steinberg);
  FloatRules rules;
  for (Solver s : kComplete) {
    std::vector<double> seen;
    SolverParams params;
    params.solver = s;
    params.progress = [&](double f) { seen.push_back(f); };
    cv::Mat grid = start.clone();
    solve(grid, rules, params);
    ASSERT_GE(seen.size(), 2u) << solver_name(s);
    for (size_t i = 0; i < seen.size(); ++i) {
      EXPECT_GE(seen[i], 0.0);
      EXPECT_LE(seen[i], 1.0);
      if (i > 0) {
        EXPECT_GE(seen[i], seen[i - 1]) << solver_name(s) << " went backwards";
      }
    }
    EXPECT_EQ(seen.back(), 1.0);

    struct Canceled {};
    params.progress = [](double f) {
      if (f > 0.2) throw Canceled{};
    };
    grid = start.clone();
    EXPECT_THROW(solve(grid, rules, params), Canceled) << solver_name(s);
  }
}

TEST(KnitSolvers, NoneKeepsTheGridAndCountsConflicts) {
  const cv::Mat start = real_grid("pic1.png", 100, Dither::threshold);
  FloatRules rules;
  cv::Mat grid = start.clone();
  SolverParams params;
  params.solver = Solver::none;
  const SolveStats stats = solve(grid, rules, params);
  EXPECT_EQ(cv::countNonZero(grid != start), 0);
  EXPECT_EQ(stats.flips, 0);
  EXPECT_EQ(stats.violations_after, stats.violations_before);
  EXPECT_GT(stats.violations_before, 0);
  EXPECT_FALSE(stats.complete);
}

TEST(KnitSolvers, NamesAndParameterChecks) {
  for (Solver s : {Solver::none, Solver::random_walk, Solver::min_conflict, Solver::gsat,
                   Solver::hybrid, Solver::texturing, Solver::hybrid_texturing})
    EXPECT_EQ(solver_from_name(solver_name(s)), s);
  EXPECT_EQ(solver_from_name("hybrid-texturing"), Solver::hybrid_texturing);
  EXPECT_TRUE(solver_is_complete(Solver::hybrid_texturing));
  EXPECT_THROW(solver_from_name("simulated-annealing"), std::invalid_argument);
  EXPECT_TRUE(solver_is_complete(Solver::gsat));
  EXPECT_FALSE(solver_is_complete(Solver::random_walk));
  EXPECT_FALSE(solver_is_complete(Solver::none));

  cv::Mat grid = random_grid(5, 20, 0.8, 1);
  FloatRules rules;
  SolverParams params;
  params.rw_n = 0;
  EXPECT_THROW(solve(grid, rules, params), std::invalid_argument);
  params = SolverParams{};
  params.rw_q = params.rw_n + 1;
  EXPECT_THROW(solve(grid, rules, params), std::invalid_argument);
  params = SolverParams{};
  rules.max_float = 1;
  EXPECT_THROW(solve(grid, rules, params), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::knit
