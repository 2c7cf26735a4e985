// Job time estimate through GRBL 1.1h's planner model (drivers/grbl/program.h over
// algorithms/laser/motion_planner.h) on a dense engrave: rows of 0.1 mm pixels at
// 6000 mm/min, M4 power per pixel, back and forth, at $120=$121=500 mm/s^2, $11=0.010.
// Counters: the estimate and length/feed (what the old estimate said), in seconds.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <string>

#include "drivers/grbl/program.h"

namespace {

using namespace atelier;

std::string dense_engrave(int rows, int pixels) {
  std::string g = "G21 G90\nM4 S0\nG1 F6000\n";
  char line[64];
  for (int row = 0; row < rows; ++row) {
    std::snprintf(line, sizeof line, "G0 X%.1f Y%.1f\n", row % 2 ? pixels * 0.1 : 0.0, row * 0.1);
    g += line;
    for (int px = 1; px <= pixels; ++px) {
      const double x = row % 2 ? (pixels - px) * 0.1 : px * 0.1;
      std::snprintf(line, sizeof line, "G1 X%.1f S%d\n", x, (px * 37 + row * 11) % 1000);
      g += line;
    }
  }
  return g + "M5\n";
}

void BM_LaserEstimateDenseEngrave(benchmark::State& state) {
  const int rows = static_cast<int>(state.range(0)), pixels = 500;
  const std::string g = dense_engrave(rows, pixels);
  const laser::MotionSettings motion =
      laser::motion_settings_from({{11, 0.010}, {110, 6000}, {111, 6000}, {120, 500}, {121, 500}});
  double seconds = 0;
  for (auto _ : state) {
    const grbl::Program p = grbl::parse_program(g, motion);
    seconds = p.total_seconds();
    benchmark::DoNotOptimize(seconds);
  }
  state.counters["estimate_s"] = seconds;
  state.counters["length_over_feed_s"] = rows * pixels * 0.1 / 100.0;
  state.counters["lines"] = rows * (pixels + 1);
  state.SetItemsProcessed(state.iterations() * rows * (pixels + 1));
}
BENCHMARK(BM_LaserEstimateDenseEngrave)->Arg(10)->Arg(100)->Arg(400)->Unit(benchmark::kMillisecond);

}  // namespace
