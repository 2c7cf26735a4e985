// The sketch target (issue 8, DESIGN.md): 1000 textured lines of 200 px in under 0.2 s, as a
// sketch job draws them (draw_sketch: the minimum-jerk path with squiggle 5, then the texture
// with a shipped pencil prepared once), on 1 and 2 threads. Input: 1000 segments of 200 px in
// random directions (fixed seed) inside a 2000 x 2000 drawing.
#include <benchmark/benchmark.h>

#include <random>

#include "algorithms/pencil/sketch.h"
#include "daemon/convert/pencil_profile_file.h"

namespace {

using namespace atelier::pencil;

std::vector<Segment> segments_200px() {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> pos(200, 1800), angle(0, 2 * CV_PI);
  std::vector<Segment> out;
  for (int i = 0; i < 1000; ++i) {
    const cv::Point2d from(pos(rng), pos(rng));
    const double a = angle(rng);
    out.push_back({from, from + 200.0 * cv::Point2d(std::cos(a), std::sin(a))});
  }
  return out;
}

// Args: pencil (0 = HB, the default; 1 = 6B, the widest common one), threads.
void BM_Sketch1000Lines(benchmark::State& state) {
  const PencilProfile pencil = atelier::shipped_pencil(state.range(0) == 0 ? "HB" : "6B");
  const std::vector<Segment> segments = segments_200px();
  for (auto _ : state) {
    SketchDrawing d = draw_sketch({2000, 2000}, 1.0, segments, {}, {}, pencil, 7, {},
                                  static_cast<int>(state.range(1)));
    benchmark::DoNotOptimize(d.canvas.data);
  }
  state.SetLabel(pencil.name + ", 1000 lines x 200 px, " + std::to_string(state.range(1)) + " thread(s)");
  state.counters["lines/s"] = benchmark::Counter(1000.0 * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Sketch1000Lines)->Args({0, 1})->Args({0, 2})->Args({1, 1})->Args({1, 2})
    ->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

}  // namespace
