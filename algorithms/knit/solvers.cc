#include "algorithms/knit/solvers.h"

#include <algorithm>
#include <random>
#include <stdexcept>
#include <vector>

#include "algorithms/knit/problem.h"

namespace atelier::knit {
namespace {

using detail::RowView;
using Rng = std::mt19937_64;

// Constraints never span two rows, so every row is an independent sub-problem: a flip in one
// row changes no other row's violations. The complete solvers therefore work row by row,
// which gives the same result as interleaving the rows in any order.

int uniform(Rng& rng, int lo, int hi) {  // inclusive bounds
  return std::uniform_int_distribution<int>(lo, hi)(rng);
}

// Reports progress in [from, to] for a phase; params.progress may throw to cancel.
class Progress {
 public:
  Progress(const std::function<void(double)>& fn, double from, double to)
      : fn_(fn), from_(from), to_(to) {}
  void operator()(double fraction) const {
    if (fn_) fn_(from_ + (to_ - from_) * std::clamp(fraction, 0.0, 1.0));
  }

 private:
  const std::function<void(double)>& fn_;
  double from_, to_;
};

constexpr int kRowsPerReport = 64;

inline void flip(RowView& r, int x) { r.cells[x] ^= 1; }

// The flip GSAT takes for a violating run [s, s + len), always an interior stitch so the run
// never merges with its neighbours. A run of at most 2f+1 is fully repaired by one flip
// anywhere that leaves both parts <= f (chosen at random). A longer run is broken f+1
// stitches from one end (chosen at random): that flip repairs f+1 windows, the most any flip
// can, and leaves one shorter run. Repeating gives floor(len / (f+1)) flips, the minimum.
// Returns the remaining violating part (length 0 when the run is repaired).
struct Remainder {
  int start, length;
};
Remainder gsat_break(RowView& r, int s, int len, Rng& rng) {
  const int f = r.max_float;
  if (len <= 2 * f + 1) {
    const int lo = std::max(1, len - 1 - f), hi = std::min(f, len - 2);
    flip(r, s + uniform(rng, lo, hi));
    return {s, 0};
  }
  if (rng() & 1) {
    flip(r, s + f);
    return {s + f + 1, len - f - 1};
  }
  flip(r, s + len - 1 - f);
  return {s, len - f - 1};
}

// GSAT on one row: best flip first among the row's violating runs, re-ranking only the run
// just broken. The rank of a run is what its best flip repairs: min(len - f, f + 1).
long gsat_row(RowView& r, Rng& rng, std::vector<Remainder>& heap) {
  const int f = r.max_float;
  heap.clear();
  r.for_each_run([&](int s, int len) {
    if (r.run_violations(s, len) > 0) heap.push_back({s, len});
  });
  auto rank = [f](const Remainder& a) { return std::min(a.length - f, f + 1); };
  auto lower = [&](const Remainder& a, const Remainder& b) {
    const int ra = rank(a), rb = rank(b);
    return ra != rb ? ra < rb : a.start > b.start;
  };
  std::make_heap(heap.begin(), heap.end(), lower);
  long flips = 0;
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), lower);
    const Remainder top = heap.back();
    heap.pop_back();
    const Remainder rest = gsat_break(r, top.start, top.length, rng);
    ++flips;
    if (rest.length > f) {
      heap.push_back(rest);
      std::push_heap(heap.begin(), heap.end(), lower);
    }
  }
  return flips;
}

long run_gsat(cv::Mat& grid, const FloatRules& rules, Rng& rng, const Progress& progress) {
  std::vector<Remainder> heap;
  long flips = 0;
  for (int y = 0; y < grid.rows; ++y) {
    if (y % kRowsPerReport == 0) progress(static_cast<double>(y) / grid.rows);
    RowView r = detail::row_view(grid, rules, y);
    flips += gsat_row(r, rng, heap);
  }
  return flips;
}

// Algorithm 4.2: each violating run is broken at a random shift in [1, f-1] and then every
// f stitches, never at its last stitch. Flips are interior, so no run merges with a
// neighbour, every piece is at most f long, and one pass leaves zero violations.
long run_texturing(cv::Mat& grid, const FloatRules& rules, Rng& rng, const Progress& progress) {
  const int f = rules.max_float;
  std::vector<Remainder> runs;
  long flips = 0;
  for (int y = 0; y < grid.rows; ++y) {
    if (y % kRowsPerReport == 0) progress(static_cast<double>(y) / grid.rows);
    RowView r = detail::row_view(grid, rules, y);
    runs.clear();
    r.for_each_run([&](int s, int len) {
      if (r.run_violations(s, len) > 0) runs.push_back({s, len});
    });
    for (const Remainder& run : runs) {
      const int last = run.start + run.length - 1;
      for (int x = run.start + uniform(rng, 1, f - 1); x < last; x += f) {
        flip(r, x);
        ++flips;
      }
    }
  }
  return flips;
}

// Flip-averse Min-Conflict on one row: a uniformly random conflicting stitch is flipped only
// if that lowers the row's (and so the grid's) violations. Keeps the row's violating runs in
// a list indexed by start column and rescans only the runs a flip touched.
class MinConflictRow {
 public:
  MinConflictRow(RowView r, Rng& rng) : r_(r), rng_(rng), slot_(r.width, -1) {
    r_.for_each_run([&](int s, int len) { add(s, len); });
  }

  long solve() {
    long flips = 0;
    int rejected = 0;
    while (!runs_.empty()) {
      long total = 0;
      for (const Remainder& run : runs_) total += run.length;
      long k = std::uniform_int_distribution<long>(0, total - 1)(rng_);
      size_t i = 0;
      while (k >= runs_[i].length) k -= runs_[i++].length;
      const Remainder run = runs_[i];
      int x = run.start + static_cast<int>(k);
      if (r_.flip_delta(x) >= 0) {
        // Rejected. Drawing at random finds an improving stitch quickly (every violating
        // run has many); after a long unlucky streak take GSAT's repairing flip so the
        // search always ends.
        if (++rejected < 64) continue;
        x = gsat_flip_position(run);
      }
      rejected = 0;
      apply(x, run);
      ++flips;
    }
    return flips;
  }

 private:
  void add(int s, int len) {
    if (r_.run_violations(s, len) == 0) return;
    slot_[s] = static_cast<int>(runs_.size());
    runs_.push_back({s, len});
  }
  void remove_at(int s) {
    const int i = slot_[s];
    if (i < 0) return;
    slot_[s] = -1;
    if (static_cast<size_t>(i) + 1 != runs_.size()) {
      runs_[i] = runs_.back();
      slot_[runs_[i].start] = i;
    }
    runs_.pop_back();
  }
  // An interior stitch that repairs at least one window (see gsat_break).
  int gsat_flip_position(const Remainder& run) const {
    const int f = r_.max_float, len = run.length;
    return run.start + (len <= 2 * f + 1 ? std::min(f, len - 2) : f);
  }
  // Flips x of violating run `run` and refreshes the list over the runs it touched.
  void apply(int x, const Remainder& run) {
    const int s = run.start, e = run.start + run.length - 1;
    int lo = s, hi = e;
    if (x == s && x > 0 && !r_.relaxed(x - 1)) lo = r_.run_start(x - 1);
    if (x == e && x + 1 < r_.width && !r_.relaxed(x + 1)) hi = r_.run_end(x + 1);
    remove_at(s);
    if (lo < s) remove_at(lo);
    if (hi > e) remove_at(e + 1);
    flip(r_, x);
    r_.for_each_run_in(lo, hi, [&](int rs, int len) { add(rs, len); });
  }

  RowView r_;
  Rng& rng_;
  std::vector<int> slot_;  // start column -> index in runs_, or -1
  std::vector<Remainder> runs_;
};

long run_min_conflict(cv::Mat& grid, const FloatRules& rules, Rng& rng,
                      const Progress& progress) {
  long flips = 0;
  for (int y = 0; y < grid.rows; ++y) {
    if (y % kRowsPerReport == 0) progress(static_cast<double>(y) / grid.rows);
    MinConflictRow row(detail::row_view(grid, rules, y), rng);
    flips += row.solve();
  }
  return flips;
}

// Start and end column of the run holding every stitch, so Random Walk checks a drawn stitch
// in O(1) however long its run. Kept up to date over just the runs a flip touches.
class RunIndex {
 public:
  RunIndex(const cv::Mat& grid, const FloatRules& rules)
      : grid_(grid), rules_(rules), start_(grid.total()), end_(grid.total()) {
    for (int y = 0; y < grid.rows; ++y) {
      const RowView r = detail::row_view(grid, rules, y);
      index(r, y, 0, grid.cols - 1);
    }
  }
  int start(int y, int x) const { return start_[offset(y, x)]; }
  // Asks the CPU to fetch what checking stitch `cell` (row-major) will read.
  void prefetch(uint64_t cell) const {
    __builtin_prefetch(grid_.data + cell);
    __builtin_prefetch(&start_[cell]);
    __builtin_prefetch(&end_[cell]);
  }
  int end(int y, int x) const { return end_[offset(y, x)]; }

  // Flips stitch x of row y and re-indexes the runs it split or joined.
  void flip_at(RowView& r, int y, int x) {
    const int s = start(y, x), e = end(y, x);
    const int lo = (x == s && x > 0 && !r.relaxed(x - 1)) ? start(y, x - 1) : s;
    const int hi = (x == e && x + 1 < r.width && !r.relaxed(x + 1)) ? end(y, x + 1) : e;
    flip(r, x);
    index(r, y, lo, hi);
  }

 private:
  size_t offset(int y, int x) const { return static_cast<size_t>(y) * grid_.cols + x; }
  void index(const RowView& r, int y, int first, int last) {
    int* starts = &start_[offset(y, 0)];
    int* ends = &end_[offset(y, 0)];
    for (int x = first; x <= last; ++x) starts[x] = ends[x] = x;  // relaxed: itself
    r.for_each_run_in(first, last, [&](int s, int len) {
      for (int x = s; x < s + len; ++x) starts[x] = s, ends[x] = s + len - 1;
    });
  }

  const cv::Mat& grid_;
  const FloatRules& rules_;
  std::vector<int> start_, end_;
};

// 4.1: rounds of n uniformly drawn stitches; a conflicting one is flipped when that drops
// the violations by at least m. Stops when fewer than q of a round's n are conflicting.
// Runs that no single flip repairs by m keep conflicting forever, so it also stops when no
// violations are left, when the last kWindow rounds flipped fewer than kWindow stitches
// (under one flip per round: the walk has run dry), or after drawing as many stitches as
// the grid holds.
long run_random_walk(cv::Mat& grid, const FloatRules& rules, const SolverParams& params,
                     long violations, Rng& rng, const Progress& progress) {
  constexpr long kWindow = 8;
  const uint64_t cells = grid.total();
  const long max_rounds = std::max<long>(kWindow, static_cast<long>(cells) / params.rw_n);
  RunIndex runs(grid, rules);
  std::vector<uint64_t> drawn(params.rw_n);
  std::vector<long> flips_by_round;
  long flips = 0;
  for (long round = 0; round < max_rounds && violations > 0; ++round) {
    if (round % 256 == 0) progress(static_cast<double>(round) / max_rounds);
    if (round >= kWindow && flips - flips_by_round[round - kWindow] < kWindow) break;
    flips_by_round.push_back(flips);
    // Draw the round's stitches first (the high bits of rng() * cells are uniform in
    // [0, cells)) and prefetch them: checks are memory bound on large grids.
    for (uint64_t& cell : drawn) {
      cell = static_cast<uint64_t>((static_cast<unsigned __int128>(rng()) * cells) >> 64);
      runs.prefetch(cell);
    }
    int conflicting = 0;
    for (const uint64_t cell : drawn) {
      const int y = static_cast<int>(cell / grid.cols), x = static_cast<int>(cell % grid.cols);
      RowView r = detail::row_view(grid, rules, y);
      if (r.relaxed(x)) continue;
      const int s = runs.start(y, x), e = runs.end(y, x);
      if (r.run_violations(s, e - s + 1) == 0) continue;
      ++conflicting;
      const int ls = (x == s && x > 0 && !r.relaxed(x - 1)) ? runs.start(y, x - 1) : x;
      const int re = (x == e && x + 1 < r.width && !r.relaxed(x + 1)) ? runs.end(y, x + 1) : x;
      const long delta = r.flip_delta(x, s, e, ls, re);
      if (-delta >= params.rw_m) {
        runs.flip_at(r, y, x);
        violations += delta;
        ++flips;
      }
    }
    if (conflicting < params.rw_q) break;
  }
  return flips;
}

void check_random_walk(const SolverParams& p) {
  if (p.rw_n < 1) throw std::invalid_argument("solve: rw_n must be at least 1");
  if (p.rw_q < 0 || p.rw_q > p.rw_n)
    throw std::invalid_argument("solve: rw_q must be within 0..rw_n");
  if (p.rw_m < 1) throw std::invalid_argument("solve: rw_m must be at least 1");
}

}  // namespace

Solver solver_from_name(const std::string& name) {
  if (name == "none") return Solver::none;
  if (name == "random-walk") return Solver::random_walk;
  if (name == "min-conflict") return Solver::min_conflict;
  if (name == "gsat") return Solver::gsat;
  if (name == "hybrid") return Solver::hybrid;
  if (name == "texturing") return Solver::texturing;
  if (name == "hybrid-texturing") return Solver::hybrid_texturing;
  throw std::invalid_argument(
      "unknown solver \"" + name +
      "\" (none, random-walk, min-conflict, gsat, hybrid, texturing, hybrid-texturing)");
}

std::string solver_name(Solver s) {
  switch (s) {
    case Solver::none: return "none";
    case Solver::random_walk: return "random-walk";
    case Solver::min_conflict: return "min-conflict";
    case Solver::gsat: return "gsat";
    case Solver::hybrid: return "hybrid";
    case Solver::texturing: return "texturing";
    case Solver::hybrid_texturing: return "hybrid-texturing";
  }
  throw std::invalid_argument("solver_name: invalid Solver value");
}

bool solver_is_complete(Solver s) {
  return s == Solver::min_conflict || s == Solver::gsat || s == Solver::hybrid ||
         s == Solver::texturing || s == Solver::hybrid_texturing;
}

SolveStats solve(cv::Mat& grid, const FloatRules& rules, const SolverParams& params) {
  detail::check_problem(grid, rules, "solve");
  if (params.solver == Solver::random_walk || params.solver == Solver::hybrid ||
      params.solver == Solver::hybrid_texturing)
    check_random_walk(params);
  SolveStats stats;
  stats.violations_before = count_violations(grid, rules);
  Rng rng(params.seed);
  const auto& fn = params.progress;
  switch (params.solver) {
    case Solver::none:
      break;
    case Solver::random_walk:
      stats.random_walk_flips = run_random_walk(grid, rules, params, stats.violations_before, rng, Progress(fn, 0, 1));
      break;
    case Solver::min_conflict:
      stats.search_flips = run_min_conflict(grid, rules, rng, Progress(fn, 0, 1));
      break;
    case Solver::gsat:
      stats.search_flips = run_gsat(grid, rules, rng, Progress(fn, 0, 1));
      break;
    case Solver::hybrid:
      stats.random_walk_flips = run_random_walk(grid, rules, params, stats.violations_before, rng, Progress(fn, 0, 0.5));
      stats.search_flips = run_gsat(grid, rules, rng, Progress(fn, 0.5, 1));
      break;
    case Solver::texturing:
      stats.search_flips = run_texturing(grid, rules, rng, Progress(fn, 0, 1));
      break;
    case Solver::hybrid_texturing:
      stats.random_walk_flips = run_random_walk(grid, rules, params, stats.violations_before, rng, Progress(fn, 0, 0.5));
      stats.search_flips = run_texturing(grid, rules, rng, Progress(fn, 0.5, 1));
      break;
  }
  if (fn) fn(1.0);
  stats.flips = stats.random_walk_flips + stats.search_flips;
  stats.violations_after = count_violations(grid, rules);
  stats.complete = stats.violations_after == 0;
  return stats;
}

void solve_hybrids(const cv::Mat& start, const FloatRules& rules, const SolverParams& params,
                   cv::Mat& by_gsat, SolveStats& gsat_stats, cv::Mat& by_texturing,
                   SolveStats& texturing_stats) {
  detail::check_problem(start, rules, "solve");
  check_random_walk(params);
  const std::function<void(double)> quiet;
  SolveStats walk;
  walk.violations_before = count_violations(start, rules);
  Rng rng(params.seed);  // as solve(): the walk draws first, the second phase continues
  cv::Mat walked = start.clone();
  walk.random_walk_flips = run_random_walk(walked, rules, params, walk.violations_before, rng, Progress(quiet, 0, 1));
  Rng rng_texturing = rng;  // the same state for the other second phase
  by_gsat = walked.clone();
  by_texturing = walked;
  gsat_stats = walk;
  gsat_stats.search_flips = run_gsat(by_gsat, rules, rng, Progress(quiet, 0, 1));
  texturing_stats = walk;
  texturing_stats.search_flips = run_texturing(by_texturing, rules, rng_texturing, Progress(quiet, 0, 1));
  for (auto [grid, stats] : {std::pair{&by_gsat, &gsat_stats}, std::pair{&by_texturing, &texturing_stats}}) {
    stats->flips = stats->random_walk_flips + stats->search_flips;
    stats->violations_after = count_violations(*grid, rules);
    stats->complete = stats->violations_after == 0;
  }
}

}  // namespace atelier::knit
