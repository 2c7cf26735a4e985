#include "algorithms/lace/evolve.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <exception>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

#include "algorithms/lace/operators.h"
#include "algorithms/lace/random_chart.h"
#include "algorithms/lace/stitch_tree.h"

namespace atelier::lace {

namespace {

// Runs fn(begin, end) over [0, n) cut into `threads` fixed contiguous chunks, chunk 0 on the
// calling thread. The first exception (by chunk) is rethrown after all have finished.
template <typename Fn>
void parallel_for(std::size_t n, int threads, Fn&& fn) {
  const std::size_t parts = std::max<std::size_t>(1, std::min<std::size_t>(threads, n));
  if (parts == 1) {
    fn(std::size_t{0}, n);
    return;
  }
  std::vector<std::exception_ptr> errors(parts);
  auto run = [&](std::size_t k) {
    try {
      fn(n * k / parts, n * (k + 1) / parts);
    } catch (...) {
      errors[k] = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(parts - 1);
  for (std::size_t k = 1; k < parts; ++k) pool.emplace_back(run, k);
  run(0);
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

int code(Symbol s) { return static_cast<int>(s) + 1; }  // 1..5; 0 = no cell

void signature_into(const Chart& chart, int stride, ChartSignature& sig) {
  const std::size_t bits = chart.rows.size() * static_cast<std::size_t>(stride);
  const std::size_t words = (bits + 63) / 64;
  sig.planes.assign(3 * words, 0);
  for (std::size_t r = 0; r < chart.rows.size(); ++r) {
    const Row& row = chart.rows[r];
    const std::size_t n = std::min<std::size_t>(row.size(), stride);
    for (std::size_t j = 0; j < n; ++j) {
      const std::size_t bit = r * stride + j;
      const int c = code(row[j]);
      for (int b = 0; b < 3; ++b) {
        if (c >> b & 1) sig.planes[b * words + bit / 64] |= std::uint64_t{1} << (bit % 64);
      }
    }
  }
}

struct Individual {
  Forest forest;
  Chart chart;  // decode(forest)
  Evaluation evaluation;
  ChartSignature signature;
  bool evaluated = false;  // chart, evaluation and signature are those of forest
};

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("lace: evolve: " + what);
}

void validate(const EvolveParams& p) {
  auto weight_ok = [](double w) { return std::isfinite(w) && w >= 0; };
  if (p.start) {
    require(p.start_cast_on >= 2 && p.start_cast_on <= 200, "start_cast_on must be 2..200");
    require(!p.start->rows.empty() && p.start->rows.size() <= 200, "start must have 1..200 rows");
    const Knittability k = knittable(*p.start, p.start_cast_on);
    require(k.ok, "start cannot be knitted from start_cast_on stitches: " + k.why);
    require(produced(p.start->rows.back()) == p.start_cast_on,
            "start must end as wide as its cast-on (eq. 1), it ends with " +
                std::to_string(produced(p.start->rows.back())) + " stitches");
  } else {
    require(p.width >= 2 && p.width <= 200, "width must be 2..200");
    require(p.rows >= 1 && p.rows <= 200, "rows must be 1..200");
  }
  require(p.population >= 2 && p.population <= 100000, "population must be 2..100000");
  require(p.generations >= 0 && p.generations <= 100000, "generations must be 0..100000");
  require(weight_ok(p.weights.holes), "weights.holes must be finite and >= 0");
  require(weight_ok(p.weights.knit_length), "weights.knit_length must be finite and >= 0");
  require(weight_ok(p.weights.depth), "weights.depth must be finite and >= 0");
  require(weight_ok(p.weights.symmetry), "weights.symmetry must be finite and >= 0");
  require(p.width_tolerance >= 0 && p.width_tolerance <= 200, "width_tolerance must be 0..200");
  require(p.tournament >= 1 && p.tournament <= p.population, "tournament must be 1..population");
  require(p.elites >= 0 && p.elites < p.population, "elites must be 0..population-1");
  require(p.crossover_rate >= 0 && p.crossover_rate <= 1, "crossover_rate must be in [0, 1]");
  require(p.mutation_rate >= 0 && p.mutation_rate <= 1, "mutation_rate must be in [0, 1]");
  require(p.sharing_radius >= 0 && p.sharing_radius <= 1, "sharing_radius must be in [0, 1]");
  require(std::isfinite(p.sharing_alpha) && p.sharing_alpha > 0, "sharing_alpha must be > 0");
  require(p.threads >= 1 && p.threads <= 64, "threads must be 1..64");
  require(weight_ok(p.weights.hole_lines), "weights.hole_lines must be finite and >= 0");
  require(weight_ok(p.weights.yo_band), "weights.yo_band must be finite and >= 0");
  require(weight_ok(p.weights.width_change), "weights.width_change must be finite and >= 0");
  require(std::isfinite(p.weights.yo_share_min) && std::isfinite(p.weights.yo_share_max) &&
              p.weights.yo_share_min >= 0 && p.weights.yo_share_min <= p.weights.yo_share_max &&
              p.weights.yo_share_max <= 1,
          "weights.yo_share_min and yo_share_max must satisfy 0 <= min <= max <= 1");
  require(!p.target_score || std::isfinite(*p.target_score), "target_score must be finite");
  require(p.stagnation >= 0 && p.stagnation <= 100000, "stagnation must be 0..100000");
}

// One random mutation (probabilities in evolve.h's file comment). Returns whether it changed
// the forest.
bool mutate(Forest& f, std::mt19937_64& rng) {
  const int x = std::uniform_int_distribution<int>(0, 19)(rng);
  if (x < 5) return subtree_mutation(f, rng);
  if (x < 7) return flip_slant(f, rng);
  if (x < 10) return lengthen_plain_run(f, rng);
  if (x < 13) return shorten_plain_run(f, rng);
  if (x < 15) return point_mutation(f, rng);
  if (x < 17) return mirror_tree(f, rng);
  return swap_trees(f, rng);
}

class Run {
 public:
  explicit Run(const EvolveParams& p)
      : p_(p),
        width_(p.start ? p.start_cast_on : p.width),
        rows_(p.start ? static_cast<int>(p.start->rows.size()) : p.rows),
        stride_(width_ + p.width_tolerance),
        sigma_(p.sharing_radius * width_ * rows_),
        rng_(p.seed) {}

  EvolveResult run() {
    int generation = 0;
    if (p_.start) {
      pop_.resize(1);
      pop_[0].forest = encode(*p_.start, p_.start_cast_on);
      pop_[0].evaluated = false;
    } else {
      random_population();
    }
    evaluate_all(0);
    record();
    if (p_.start && p_.generations >= 1) {
      variations_of_start();
      evaluate_all(0);
      record();
      report(++generation);
    }
    next_.resize(p_.population);
    std::string stopped_by = "generations";
    int since_better = 0;  // generations without a better feasible chart
    double best_seen = best_ ? best_->evaluation.score : -std::numeric_limits<double>::infinity();
    while (generation < p_.generations) {
      if (p_.target_score && best_ && best_->evaluation.score >= *p_.target_score) {
        stopped_by = "target_score";
        break;
      }
      if (p_.stagnation > 0 && since_better >= p_.stagnation) {
        stopped_by = "stagnation";
        break;
      }
      breed();
      pop_.swap(next_);
      evaluate_all(0);  // elites and unchanged copies are skipped
      record();
      report(++generation);
      if (best_ && best_->evaluation.score > best_seen) {
        best_seen = best_->evaluation.score;
        since_better = 0;
      } else {
        ++since_better;
      }
    }
    if (stopped_by == "generations" && p_.target_score && best_ && best_->evaluation.score >= *p_.target_score) {
      stopped_by = "target_score";
    }
    if (!best_) {
      throw std::runtime_error(
          "lace: evolve: no chart satisfied the constraints (the extra constraints rejected every "
          "chart, or the start chart is infeasible and there were no generations)");
    }
    EvolveResult result;
    result.chart = best_->chart;
    result.cast_on = width_;
    result.evaluation = best_->evaluation;
    result.generations_run = generation;
    result.stopped_by = stopped_by;
    result.best_score = std::move(best_score_);
    result.feasible_in_final_population = static_cast<int>(std::count_if(
        pop_.begin(), pop_.end(), [](const Individual& i) { return i.evaluation.constraints.ok(); }));
    return result;
  }

 private:
  // Half grown trees (shape variety), half row-by-row charts that satisfy the constraints (half
  // of those mirror-symmetric).
  void random_population() {
    pop_.resize(p_.population);
    for (std::size_t i = 0; i < pop_.size(); ++i) {
      // Every fourth a mirror-symmetric row-by-row chart (not for the carriage: see
      // random_symmetric_chart()), every other one a feasible row-by-row chart, the rest grown.
      if (i % 4 == 2 && !p_.carriage_pairings) pop_[i].forest = encode(random_symmetric_chart(width_, rows_, rng_), width_);
      else if (i % 2 == 0) pop_[i].forest = encode(random_feasible_chart(width_, rows_, rng_, p_.carriage_pairings), width_);
      else pop_[i].forest = random_forest(width_, rows_, rng_);
      pop_[i].evaluated = false;
    }
    add_plain_chart_for_extra_constraints();
  }

  // Extra constraints (e.g. the lace carriage's) may reject every random chart; a plain chart
  // (all k: no transfers, nothing to balance) satisfies any of them, so one is always there.
  void add_plain_chart_for_extra_constraints() {
    if (!p_.extra_violations || pop_.size() < 2) return;
    Chart plain;
    plain.rows.assign(rows_, Row(width_, Symbol::k));
    pop_.back().forest = encode(plain, width_);
    pop_.back().evaluated = false;
  }

  // The start chart, then mutants of it (1 to 3 mutations each); with an infeasible start, every
  // other individual is a random feasible chart so that a feasible chart exists.
  void variations_of_start() {
    const Forest start = pop_[0].forest;
    const bool feasible = pop_[0].evaluation.constraints.ok();
    pop_.resize(p_.population);
    for (std::size_t i = 1; i < pop_.size(); ++i) {
      pop_[i].evaluated = false;
      if (!feasible && i % 2 == 1) {
        pop_[i].forest = encode(random_feasible_chart(width_, rows_, rng_, p_.carriage_pairings), width_);
        continue;
      }
      pop_[i].forest = start;
      const int n = std::uniform_int_distribution<int>(1, 3)(rng_);
      for (int m = 0; m < n; ++m) mutate(pop_[i].forest, rng_);
    }
    add_plain_chart_for_extra_constraints();
  }

  void evaluate_all(std::size_t from) {
    parallel_for(pop_.size() - from, p_.threads, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = from + begin; i < from + end; ++i) {
        if (!pop_[i].evaluated) evaluate_one(pop_[i]);
      }
    });
  }

  void evaluate_one(Individual& ind) const {
    decode_into(ind.forest, ind.chart);
    Evaluation& e = ind.evaluation;
    e = evaluate(ind.chart, width_, p_.weights, p_.width_tolerance);
    if (p_.extra_violations) {
      e.constraints.extra = p_.extra_violations(ind.chart, width_);
      if (e.constraints.extra < 0) {
        throw std::invalid_argument("lace: evolve: extra_violations returned a negative count");
      }
      e.score = score(e.constraints, e.objectives, p_.weights);
    }
    signature_into(ind.chart, stride_, ind.signature);
    ind.evaluated = true;
  }

  // Best raw score of the generation, and the best feasible individual ever (first seen wins
  // ties).
  void record() {
    double top = -std::numeric_limits<double>::infinity();
    for (const Individual& ind : pop_) {
      top = std::max(top, ind.evaluation.score);
      if (ind.evaluation.constraints.ok() &&
          (!best_ || ind.evaluation.score > best_->evaluation.score)) {
        best_ = ind;
      }
    }
    best_score_.push_back(top);
  }

  void report(int generation) const {
    if (p_.progress) p_.progress(generation, p_.generations);
  }

  // Shared fitness: scores shifted to be positive, divided by the niche counts.
  void share() {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const Individual& ind : pop_) {
      lo = std::min(lo, ind.evaluation.score);
      hi = std::max(hi, ind.evaluation.score);
    }
    const double floor = 1e-9 + 0.01 * (hi - lo);  // the worst keeps a small chance
    signatures_.resize(pop_.size());
    for (std::size_t i = 0; i < pop_.size(); ++i) std::swap(signatures_[i], pop_[i].signature);
    const std::vector<double> niches = niche_counts(signatures_, sigma_, p_.sharing_alpha, p_.threads);
    for (std::size_t i = 0; i < pop_.size(); ++i) std::swap(signatures_[i], pop_[i].signature);
    shared_.resize(pop_.size());
    for (std::size_t i = 0; i < pop_.size(); ++i) {
      shared_[i] = (pop_[i].evaluation.score - lo + floor) / niches[i];
    }
  }

  // Deb's constrained tournament: a feasible individual beats an infeasible one, fewer
  // violations beat more, and otherwise the higher shared fitness wins. (The penalty alone is
  // not enough once shared: dividing by crowded niche counts would let barely-infeasible
  // loners outbid the feasible crowd.)
  bool beats(std::size_t a, std::size_t b) const {
    const int va = pop_[a].evaluation.constraints.total(), vb = pop_[b].evaluation.constraints.total();
    if (va != vb) return va < vb;
    return shared_[a] > shared_[b];
  }

  std::size_t tournament() {
    std::uniform_int_distribution<std::size_t> any(0, pop_.size() - 1);
    std::size_t winner = any(rng_);
    for (int k = 1; k < p_.tournament; ++k) {
      const std::size_t other = any(rng_);
      if (beats(other, winner)) winner = other;
    }
    return winner;
  }

  void breed() {
    share();
    std::vector<std::size_t> order(pop_.size());
    std::iota(order.begin(), order.end(), 0);
    const std::size_t elites = static_cast<std::size_t>(p_.elites);
    std::partial_sort(order.begin(), order.begin() + elites, order.end(),
                      [&](std::size_t a, std::size_t b) {
                        const double sa = pop_[a].evaluation.score, sb = pop_[b].evaluation.score;
                        return sa != sb ? sa > sb : a < b;
                      });
    for (std::size_t e = 0; e < elites; ++e) next_[e] = pop_[order[e]];
    std::uniform_real_distribution<double> coin(0.0, 1.0);
    for (std::size_t i = elites; i < next_.size(); ++i) {
      const std::size_t parent = tournament();
      Forest& child = next_[i].forest;
      child = pop_[parent].forest;  // reuses the child's storage
      bool changed = false;
      if (coin(rng_) < p_.crossover_rate) changed = crossover(child, pop_[tournament()].forest, rng_);
      if (coin(rng_) < p_.mutation_rate) changed = mutate(child, rng_) || changed;
      // An unchanged copy keeps its parent's evaluation: evaluating it again would give the same.
      if (changed) next_[i].evaluated = false;
      else next_[i] = pop_[parent];
    }
  }

  const EvolveParams& p_;
  const int width_, rows_, stride_;
  const double sigma_;
  std::mt19937_64 rng_;
  std::vector<Individual> pop_, next_;
  std::vector<ChartSignature> signatures_;
  std::vector<double> shared_;
  std::optional<Individual> best_;
  std::vector<double> best_score_;
};

}  // namespace

ChartSignature signature(const Chart& chart, int stride) {
  if (stride < 1) throw std::invalid_argument("lace: signature: stride must be >= 1");
  ChartSignature sig;
  signature_into(chart, stride, sig);
  return sig;
}

namespace {

// Cells that differ, counting stops once `limit` is reached (the pair shares no niche then).
// Built twice, the CPU's popcount instruction picked at load time where it has one.
__attribute__((target_clones("popcnt", "default"))) int distance_up_to(const ChartSignature& a,
                                                                        const ChartSignature& b,
                                                                        int limit) {
  const std::size_t words = std::min(a.planes.size(), b.planes.size()) / 3;
  const std::uint64_t* pa = a.planes.data();
  const std::uint64_t* pb = b.planes.data();
  int d = 0;
  for (std::size_t w = 0; w < words && d < limit; ++w) {
    const std::uint64_t differ = (pa[w] ^ pb[w]) | (pa[words + w] ^ pb[words + w]) |
                                 (pa[2 * words + w] ^ pb[2 * words + w]);
    d += std::popcount(differ);
  }
  return d;
}

}  // namespace

int distance(const ChartSignature& a, const ChartSignature& b) {
  return distance_up_to(a, b, std::numeric_limits<int>::max());
}

std::vector<double> niche_counts(const std::vector<ChartSignature>& population, double sigma,
                                 double alpha, int threads) {
  const std::size_t n = population.size();
  std::vector<double> m(n, 1.0);
  if (sigma <= 0 || n == 0) return m;
  // sh(d) for every integer distance below sigma, in fixed point (2^-32): integer sums do not
  // depend on their order, so the pairs can be split among threads and each pair looked at
  // once (d_ij = d_ji) with a result independent of the thread count.
  constexpr double kOne = 4294967296.0;
  std::vector<std::int64_t> sh;
  for (int d = 0; d < sigma; ++d) sh.push_back(std::llround((1.0 - std::pow(d / sigma, alpha)) * kOne));
  const int limit = static_cast<int>(sh.size());
  const std::size_t parts = std::max<std::size_t>(1, std::min<std::size_t>(threads, n));
  std::vector<std::vector<std::int64_t>> sums(parts, std::vector<std::int64_t>(n, 0));
  parallel_for(parts, static_cast<int>(parts), [&](std::size_t begin, std::size_t end) {
    for (std::size_t part = begin; part < end; ++part) {
      std::vector<std::int64_t>& sum = sums[part];
      // Interleaved rows of the triangle i < j keep the parts about equally long.
      for (std::size_t i = part; i < n; i += parts) {
        sum[i] += sh[0];
        for (std::size_t j = i + 1; j < n; ++j) {
          const int d = distance_up_to(population[i], population[j], limit);
          if (d < limit) {
            sum[i] += sh[d];
            sum[j] += sh[d];
          }
        }
      }
    }
  });
  for (std::size_t i = 0; i < n; ++i) {
    std::int64_t total = 0;
    for (std::size_t part = 0; part < parts; ++part) total += sums[part][i];
    m[i] = static_cast<double>(total) / kOne;
  }
  return m;
}

EvolveResult evolve(const EvolveParams& p) {
  validate(p);
  return Run(p).run();
}

}  // namespace atelier::lace
