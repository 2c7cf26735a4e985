// Cut planning (algorithms/laser/plan.h) of n separate rectangles, each with a hole (so the
// nesting has work to do): the planner was quadratic (20k rectangles 10 s, 200k past the
// job timeout); with its R-trees it is n log n. The label gives the input size.
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>
#include <vector>

#include "algorithms/laser/plan.h"

namespace {

using namespace atelier::laser;

Path rect(double x, double y, double w, double h) {
  return Path{{{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}}, true};
}

// `n` paths on a square grid within 400 x 400 mm: n/2 outlines, each holding a hole.
Layer grid_layer(size_t n) {
  Layer l;
  l.settings.name = "cut";
  l.settings.color = "#000000";
  l.settings.mode = Mode::cut;
  const size_t pieces = n / 2;
  const size_t side = static_cast<size_t>(std::ceil(std::sqrt(static_cast<double>(pieces))));
  const double pitch = 400.0 / static_cast<double>(side);
  for (size_t i = 0; i < pieces; ++i) {
    const double x = static_cast<double>(i % side) * pitch, y = static_cast<double>(i / side) * pitch;
    l.paths.push_back(rect(x + 0.1 * pitch, y + 0.1 * pitch, 0.8 * pitch, 0.8 * pitch));
    l.paths.push_back(rect(x + 0.3 * pitch, y + 0.3 * pitch, 0.4 * pitch, 0.4 * pitch));
  }
  return l;
}

void BM_LaserPlanRectangles(benchmark::State& state) {
  const size_t n = static_cast<size_t>(state.range(0));
  const std::vector<Layer> layers = {grid_layer(n)};
  Machine machine;
  Job job;
  for (auto _ : state) {
    job = plan_job(layers, machine);
    benchmark::DoNotOptimize(job.gcode.data());
  }
  state.SetLabel(std::to_string(layers[0].paths.size()) + " rectangles, " +
                 std::to_string(job.gcode.size() / 1000) + " kB of G-code");
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n));
}

BENCHMARK(BM_LaserPlanRectangles)->Arg(2000)->Arg(20000)->Arg(200000)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
