// Lace genetic programming (Ekart 2007): one whole evolution at the size, population
// 500 x 200 generations, a 12-stitch x 16-row chart, 2 evaluation threads. Target: < 2 s.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <string>

#include "algorithms/lace/evolve.h"

namespace {

using namespace atelier::lace;

void BM_LaceEvolve(benchmark::State& state) {
  EvolveParams p;
  p.population = static_cast<int>(state.range(0));
  p.generations = static_cast<int>(state.range(1));
  p.threads = static_cast<int>(state.range(2));
  double score = 0;
  int feasible = 0;
  for (auto _ : state) {
    const EvolveResult r = evolve(p);
    score = r.evaluation.score;
    feasible = r.feasible_in_final_population;
    benchmark::DoNotOptimize(r.chart.rows.data());
  }
  state.SetLabel("pop " + std::to_string(p.population) + " x " + std::to_string(p.generations) +
                 " gen, " + std::to_string(p.width) + "x" + std::to_string(p.rows) + " chart, " +
                 std::to_string(p.threads) + " threads");
  state.counters["best_score"] = score;
  state.counters["feasible_final"] = feasible;
  state.SetItemsProcessed(state.iterations() * p.population * p.generations);
}

BENCHMARK(BM_LaceEvolve)->Args({500, 200, 2})->Unit(benchmark::kMillisecond)->UseRealTime();

// The converter's defaults (lace_params.h): as above but stopping after 100 generations without
// a better chart (issue 22: stop when good enough), seeds 1-3 in turn; reports the design
// figures of the last chart.
void BM_LaceEvolveDefaults(benchmark::State& state) {
  EvolveParams p;
  p.stagnation = 100;
  std::uint64_t seed = 0;
  int generations = 0;
  double yo_share = 0, hole_lines = 0, symmetry = 0;
  for (auto _ : state) {
    p.seed = 1 + seed++ % 3;
    const EvolveResult r = evolve(p);
    generations = r.generations_run;
    yo_share = r.evaluation.objectives.yo_share;
    hole_lines = r.evaluation.objectives.hole_lines;
    symmetry = r.evaluation.objectives.symmetry;
    benchmark::DoNotOptimize(r.chart.rows.data());
  }
  state.counters["generations"] = generations;
  state.counters["yo_share"] = yo_share;
  state.counters["hole_lines"] = hole_lines;
  state.counters["symmetry"] = symmetry;
}

BENCHMARK(BM_LaceEvolveDefaults)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

}  // namespace
