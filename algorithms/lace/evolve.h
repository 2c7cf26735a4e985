// Koza-style genetic programming of lace charts (Ekart 2007, section 5 and 7): a population of
// forests (stitch_tree.h; the number of trees = the repeat width, fixed; the rows fixed),
// evaluated by fitness.h, bred by tournament selection on shared fitness (Goldberg's fitness
// sharing keeps the population diverse), subtree crossover and the mutations of operators.h,
// with elitism. Tournaments follow Deb's rule for constraints: fewer violations win, and among
// equally many (feasible ones: none) the higher shared fitness wins. Shared fitness = (score -
// the population's lowest score + a floor of 1% of the score range) / niche count.
//
// One generation: the `elites` best individuals by raw score are copied unchanged; every other
// child is made from a tournament winner: with probability crossover_rate it gets a subtree of a
// second tournament winner (crossover), else it is a copy; then with probability mutation_rate
// it gets one mutation, picked with probabilities 0.25 subtree mutation, 0.1 flip a slant,
// 0.15 lengthen a plain run, 0.15 shorten a plain run, 0.1 point mutation, 0.1 mirror a tree,
// 0.15 swap two trees (operators.h).
//
// Reproducible: one std::mt19937_64 seeded from `seed` makes every random choice, on the
// calling thread, in a fixed order. Evaluation and niche counts run on `threads` threads over a
// fixed partition of the population, and neither depends on the partition, so the same seed
// and parameters give the identical chart whatever the thread count or timing. evolve() shares
// no state between calls, so several may run at once (each starts its own threads).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/fitness.h"

namespace atelier::lace {

struct EvolveParams {
  int width = 12, rows = 16;  // stitches per repeat (= trees = cast-on), chart rows (RS rows)
  int population = 500, generations = 200;
  Weights weights;
  // Stitches an intermediate row may differ from the cast-on and from the first row.
  int width_tolerance = 2;
  std::uint64_t seed = 1;
  int tournament = 4, elites = 2;
  double crossover_rate = 0.8, mutation_rate = 0.2;  // see the file comment
  // Fitness sharing: sigma, the niche radius, as a fraction of the chart's cells (width *
  // rows); 0 turns sharing off. sh(d) = 1 - (d / sigma)^alpha for d < sigma.
  double sharing_radius = 0.15, sharing_alpha = 1.0;
  // Variations of an existing chart: it must be knittable from start_cast_on and end as wide
  // (eq. 1). Then width = start_cast_on and rows = its rows (the fields above are ignored).
  // Generation 0 is the start chart alone; generation 1 is the start chart plus mutants of it
  // (and, if the start chart violates a constraint, half row-by-row random feasible charts).
  std::optional<Chart> start;
  int start_cast_on = 0;
  int threads = 2;  // 1..64
  // Extra constraint violations counted like the others (0 = fine), e.g. rows the knitting
  // machine's lace carriage cannot do. Called from the evaluation threads concurrently, so it
  // must be thread-safe. May be empty. When set, generation 0 (and 1, from a start chart)
  // also holds the plain chart (all k), which needs no transfers, so that a feasible chart
  // exists whenever the extra constraints accept plain knitting.
  std::function<int(const Chart&, int cast_on)> extra_violations;
  // The first generation's row-by-row charts pair yarn-overs and decreases only as a lace
  // carriage can (random_chart.h), so that charts for the machine start with lace in them.
  bool carriage_pairings = false;
  // The paper's stopping rule (section 5 step 2: stop "if the resulted pattern is acceptable"):
  // the run ends before `generations` once the best feasible chart scores at least
  // target_score (when set), or when the best feasible score has not risen for `stagnation`
  // generations in a row (0 = never). `generations` stays the bound.
  std::optional<double> target_score;
  int stagnation = 0;
  // Called on the calling thread after each generation (1..generations). May be empty.
  std::function<void(int generation, int generations)> progress;
};

struct EvolveResult {
  Chart chart;  // the best feasible chart ever seen (constraints ok, worked over cast_on)
  int cast_on = 0;  // == the width
  Evaluation evaluation;  // of chart, constraints.extra included
  int generations_run = 0;
  // Best raw score of the population in generation 0, 1, ..., generations_run (generation 0
  // of a start chart is the start chart alone).
  std::vector<double> best_score;
  int feasible_in_final_population = 0;
  // Why the run ended: "target_score", "stagnation" or "generations" (the bound).
  std::string stopped_by = "generations";
};

// Throws std::invalid_argument naming the field for bad parameters (width 2..200, rows
// 1..200, population 2..100000, generations 0..100000, weights >= 0 and finite,
// width_tolerance 0..200, tournament 1..population, elites 0..population-1, rates in [0, 1],
// sharing_radius in [0, 1], sharing_alpha > 0, threads 1..64, target_score finite,
// stagnation 0..100000, 0 <= weights.yo_share_min <= weights.yo_share_max <= 1, a start chart that cannot be
// knitted from start_cast_on or does not end as wide). Throws std::runtime_error when no
// feasible chart was ever seen (only possible when extra_violations rejects them all, or with
// an infeasible start chart and generations = 0). Exceptions from the callbacks propagate.
EvolveResult evolve(const EvolveParams& p);

// The cheap chart distance of fitness sharing: the chart's cells packed as 3-bit symbol codes
// (0 = no cell) on a grid of `stride` columns per row, cells j >= stride left out.
struct ChartSignature {
  std::vector<std::uint64_t> planes;  // 3 bit planes of words_per_plane words each
};
ChartSignature signature(const Chart& chart, int stride);
// Number of grid positions whose codes differ (Hamming distance on cells). Signatures of
// charts with the same rows and stride.
int distance(const ChartSignature& a, const ChartSignature& b);

// Goldberg's niche counts: m_i = sum over j (i itself included) of sh(d_ij), sh(d) = 1 -
// (d / sigma)^alpha for d < sigma, else 0. sigma <= 0 gives every m_i = 1 (no sharing).
// sh is summed in fixed point (units of 2^-32, so exact for identical charts). Computed on
// `threads` threads; the result does not depend on their number.
std::vector<double> niche_counts(const std::vector<ChartSignature>& population, double sigma,
                                 double alpha, int threads);

}  // namespace atelier::lace
