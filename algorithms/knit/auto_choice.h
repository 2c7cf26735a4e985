// `dither = "auto"` / `solver = "auto"` by measurement (issue 22): every candidate starting
// assignment x complete solver is run and scored by blurred SSIM; the best with zero
// violations wins. The dithers and solvers take milliseconds on a typical chart, so trying
// them all is cheaper than guessing from the picture.
//
// Pure. Candidates run on up to `threads` worker threads; each owns its grid and RNG (seeded
// from SolverParams::seed), and the winner is chosen by a fixed order, so the result does not
// depend on the thread count or on scheduling.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "algorithms/knit/dither.h"
#include "algorithms/knit/floats.h"
#include "algorithms/knit/solvers.h"

namespace atelier::knit {

struct AutoCandidate {
  Dither dither = Dither::threshold;
  Solver solver = Solver::hybrid;
  double similarity = 0;     // blurred SSIM (sigma 2 stitches) of the solved grid
  long violations = 0;       // left after solving (0 for complete solvers)
  long flips = 0;
};

struct AutoResult {
  std::vector<AutoCandidate> candidates;  // in the order tried (dithers outer, solvers inner)
  size_t chosen = 0;                      // index into candidates
  std::string reason;                     // one sentence for report.json
  cv::Mat start;                          // the chosen dither's grid
  cv::Mat grid;                           // the chosen pair's solved grid
  SolveStats stats;                       // of the chosen pair's solve
};

// The dithers and complete solvers tried when the setting is "auto".
std::vector<Dither> auto_dither_candidates();
std::vector<Solver> auto_solver_candidates();

// Tries every (dither, solver) pair on `gray` (CV_8UC1, the stitch grid). `params` gives the
// seed and Random Walk settings (its solver and progress are ignored); `threshold` is the
// dithers' threshold. Highest similarity among zero-violation results wins (ties: the earlier
// candidate); when none reaches zero, the fewest violations. `dithers` and `solvers` must not
// be empty and must not hold Dither::automatic (std::invalid_argument).
AutoResult choose_by_measurement(const cv::Mat& gray, const FloatRules& rules,
                                 const std::vector<Dither>& dithers,
                                 const std::vector<Solver>& solvers, int threshold,
                                 const SolverParams& params, int threads = 2);

}  // namespace atelier::knit
