#include "algorithms/knit/auto_choice.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <stdexcept>
#include <thread>

#include "algorithms/knit/similarity.h"

namespace atelier::knit {

std::vector<Dither> auto_dither_candidates() {
  return {Dither::threshold, Dither::floyd_steinberg, Dither::atkinson, Dither::ordered};
}

std::vector<Solver> auto_solver_candidates() {
  return {Solver::hybrid, Solver::hybrid_texturing, Solver::gsat, Solver::texturing};
}

AutoResult choose_by_measurement(const cv::Mat& gray, const FloatRules& rules,
                                 const std::vector<Dither>& dithers,
                                 const std::vector<Solver>& solvers, int threshold,
                                 const SolverParams& params, int threads) {
  if (dithers.empty() || solvers.empty())
    throw std::invalid_argument("choose_by_measurement: no candidates");
  for (Dither d : dithers)
    if (d == Dither::automatic)
      throw std::invalid_argument("choose_by_measurement: \"auto\" is not a candidate dither");
  const BlurredSsim ssim(gray, 2.0);
  std::vector<cv::Mat> starts(dithers.size());
  for (size_t i = 0; i < dithers.size(); ++i) starts[i] = dither(gray, dithers[i], threshold);

  AutoResult result;
  for (Dither d : dithers)
    for (Solver s : solvers) result.candidates.push_back(AutoCandidate{d, s});
  const size_t n = result.candidates.size();

  // Work items: one candidate, or the two hybrids of one dither together (they share their
  // Random Walk: solve_hybrids). Workers take items by index; every item writes only its
  // own candidates' slots. Each solve copies its start and seeds its own RNG, so the outcome
  // is the same however they run.
  struct Item {
    size_t first, second;  // candidate indices; second == n: a single candidate
  };
  std::vector<Item> items;
  const auto at = [&](Solver s) {
    return static_cast<size_t>(std::find(solvers.begin(), solvers.end(), s) - solvers.begin());
  };
  const size_t hy = at(Solver::hybrid), ht = at(Solver::hybrid_texturing);
  const bool pair = hy < solvers.size() && ht < solvers.size();
  for (size_t d = 0; d < dithers.size(); ++d)
    for (size_t k = 0; k < solvers.size(); ++k) {
      const size_t i = d * solvers.size() + k;
      if (pair && k == ht) continue;  // done with its hybrid
      items.push_back({i, pair && k == hy ? d * solvers.size() + ht : n});
    }
  std::atomic<size_t> next{0};
  std::vector<std::string> errors(n);
  auto record = [&](size_t i, const cv::Mat& grid, const SolveStats& st) {
    AutoCandidate& c = result.candidates[i];
    c.violations = st.violations_after;
    c.flips = st.flips;
    c.similarity = ssim(grid);
  };
  auto work = [&] {
    for (size_t j; (j = next.fetch_add(1)) < items.size();) {
      const Item& item = items[j];
      try {
        const cv::Mat& start = starts[item.first / solvers.size()];
        SolverParams sp = params;
        sp.progress = nullptr;
        if (item.second < n) {
          cv::Mat a, b;
          SolveStats sa, sb;
          solve_hybrids(start, rules, sp, a, sa, b, sb);
          record(item.first, a, sa);
          record(item.second, b, sb);
        } else {
          cv::Mat grid = start.clone();
          sp.solver = result.candidates[item.first].solver;
          const SolveStats st = solve(grid, rules, sp);
          record(item.first, grid, st);
        }
      } catch (const std::exception& e) {
        errors[item.first] = e.what();
      }
    }
  };
  const int workers = std::clamp(threads, 1, static_cast<int>(items.size()));
  std::vector<std::thread> pool;
  for (int t = 1; t < workers; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  for (const std::string& e : errors)
    if (!e.empty()) throw std::invalid_argument(e);

  // Best: zero violations first, then the highest similarity; ties keep the earlier one.
  auto better = [](const AutoCandidate& a, const AutoCandidate& b) {
    const bool ca = a.violations == 0, cb = b.violations == 0;
    if (ca != cb) return ca;
    if (!ca && a.violations != b.violations) return a.violations < b.violations;
    return a.similarity > b.similarity;
  };
  for (size_t i = 1; i < n; ++i)
    if (better(result.candidates[i], result.candidates[result.chosen])) result.chosen = i;
  const AutoCandidate& best = result.candidates[result.chosen];

  // Re-run the winner (deterministic: same start, same seed) rather than keeping every grid.
  result.start = starts[result.chosen / solvers.size()];
  result.grid = result.start.clone();
  SolverParams sp = params;
  sp.solver = best.solver;
  sp.progress = nullptr;
  result.stats = solve(result.grid, rules, sp);

  size_t complete = 0;
  double runner_up = -2;
  for (size_t i = 0; i < n; ++i) {
    const AutoCandidate& c = result.candidates[i];
    if (c.violations == 0) ++complete;
    if (i != result.chosen && c.violations == 0) runner_up = std::max(runner_up, c.similarity);
  }
  char text[400];
  if (best.violations == 0) {
    std::snprintf(text, sizeof text,
                  "highest blurred SSIM (%.4f) of the %zu candidates with no float longer than "
                  "max_float, out of %zu tried%s",
                  best.similarity, complete, n,
                  runner_up > -2 ? (", next best " + std::to_string(runner_up).substr(0, 6)).c_str() : "");
  } else {
    std::snprintf(text, sizeof text,
                  "no candidate reached zero violations; fewest violations (%ld) of %zu tried",
                  best.violations, n);
  }
  result.reason = text;
  return result;
}

}  // namespace atelier::knit
