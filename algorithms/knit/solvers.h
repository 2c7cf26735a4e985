// Local-search solvers for the float CSP (paper section 4), all seeded and reproducible.
//
// Pure, thread-safe (each call owns its RNG). The grid is modified in place.
#pragma once

#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <string>

#include "algorithms/knit/floats.h"

namespace atelier::knit {

enum class Solver {
  none,          // keep the starting assignment
  random_walk,   // 4.1: random variables, flip if it repairs >= m; stop when < q of n conflict
  min_conflict,  // 4.2: flip-averse Min-Conflict, runs to a complete solution
  gsat,          // 4.3: best flip first, row-local re-ranking, minimal flips
  hybrid,        // 4.4: Random Walk (n, q, m) then GSAT
  texturing,     // 4.5: break each long run at a random shift, every f stitches
  // The paper's second hybrid (abstract, 4.4-4.5, 6: Atkinson + texturing "resembles the
  // original the best"): Random Walk (n, q, m) for randomness, then pseudo-random texturing
  // instead of GSAT for what is left. GSAT's breaks sit f + 1 from a run's end and line up
  // beside vertical structure; texturing's random shift does not align them (at the cost of
  // more flips than GSAT's minimum). m = 2f+1 reduces it to texturing.
  hybrid_texturing,
};

// "none", "random-walk", "min-conflict", "gsat", "hybrid", "texturing", "hybrid-texturing".
Solver solver_from_name(const std::string& name);  // throws std::invalid_argument
std::string solver_name(Solver s);
// True for the solvers that always end with zero violations.
bool solver_is_complete(Solver s);

struct SolverParams {
  Solver solver = Solver::hybrid;
  uint64_t seed = 1;
  int rw_n = 100;   // Random Walk: variables checked per round
  int rw_q = 5;     // Random Walk: stop when fewer than q of the n are conflicting
  int rw_m = 4;     // Random Walk: flip only when violations drop by at least m
  // Random Walk also stops when no violations are left, when its last 8 rounds flipped fewer
  // than 8 stitches (no flip repairs m any more), or after drawing as many stitches as the
  // grid holds. Requires n >= 1, 0 <= q <= n, m >= 1 (std::invalid_argument otherwise).
  // Called now and then with a fraction in [0, 1]; may be empty. Not called concurrently.
  std::function<void(double)> progress;
};

struct SolveStats {
  long violations_before = 0;
  long violations_after = 0;
  long flips = 0;             // total stitches flipped
  long random_walk_flips = 0; // of which by the Random Walk phase (random_walk, hybrid*)
  long search_flips = 0;      // of which by GSAT / Min-Conflict / texturing
  bool complete = false;      // violations_after == 0
};

SolveStats solve(cv::Mat& grid, const FloatRules& rules, const SolverParams& params);

// Both hybrids from one Random Walk, their common first phase (the auto search runs both):
// `by_gsat` ends as solve() with Solver::hybrid and `by_texturing` as with
// Solver::hybrid_texturing would leave `start`, with the same params (params.solver and
// progress are ignored). Same checks and exceptions as solve().
void solve_hybrids(const cv::Mat& start, const FloatRules& rules, const SolverParams& params,
                   cv::Mat& by_gsat, SolveStats& gsat_stats, cv::Mat& by_texturing,
                   SolveStats& texturing_stats);

}  // namespace atelier::knit
