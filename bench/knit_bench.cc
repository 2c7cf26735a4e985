// Knit benchmarks: every dither and every solver on grids made from a real painting
// (tests/data/starry_night.jpg) at the paper's 363x255 and at 2000x2000.
#include <benchmark/benchmark.h>

#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <utility>

#include "algorithms/knit/dither.h"
#include "algorithms/knit/solvers.h"
#include "algorithms/knit/stitch_grid.h"

namespace {

using namespace atelier::knit;

const cv::Mat& painting() {
  static const cv::Mat image = [] {
    const std::string path = std::string(ATELIER_TEST_DATA) + "/starry_night.jpg";
    cv::Mat m = cv::imread(path, cv::IMREAD_GRAYSCALE);
    if (m.empty()) throw std::runtime_error("knit_bench: cannot read " + path);
    return m;
  }();
  return image;
}

// Grey stitch grid of exactly cols x rows (the painting resized, as the gauge step would).
const cv::Mat& gray_grid(int cols, int rows) {
  static std::map<std::pair<int, int>, cv::Mat> cache;
  cv::Mat& g = cache[{cols, rows}];
  if (g.empty()) cv::resize(painting(), g, cv::Size(cols, rows), 0, 0,
                            cols < painting().cols ? cv::INTER_AREA : cv::INTER_LINEAR);
  return g;
}

const cv::Mat& fs_grid(int cols, int rows) {
  static std::map<std::pair<int, int>, cv::Mat> cache;
  cv::Mat& g = cache[{cols, rows}];
  if (g.empty()) g = dither(gray_grid(cols, rows), Dither::floyd_steinberg);
  return g;
}

std::string size_label(int cols, int rows) {
  return std::to_string(cols) + "x" + std::to_string(rows);
}

void BM_KnitDither(benchmark::State& state, Dither method) {
  const int cols = static_cast<int>(state.range(0)), rows = static_cast<int>(state.range(1));
  const cv::Mat& gray = gray_grid(cols, rows);
  for (auto _ : state) benchmark::DoNotOptimize(dither(gray, method));
  state.SetLabel(size_label(cols, rows) + " " + dither_name(method));
  state.SetItemsProcessed(state.iterations() * gray.total());
}

void BM_KnitSolve(benchmark::State& state, Solver solver) {
  const int cols = static_cast<int>(state.range(0)), rows = static_cast<int>(state.range(1));
  const cv::Mat& start = fs_grid(cols, rows);
  FloatRules rules;  // f = 4, anchored: the paper's defaults
  SolverParams params;
  params.solver = solver;
  cv::Mat grid;
  SolveStats stats;
  for (auto _ : state) {
    state.PauseTiming();
    start.copyTo(grid);
    state.ResumeTiming();
    stats = solve(grid, rules, params);
    benchmark::DoNotOptimize(grid.data);
  }
  state.SetLabel(size_label(cols, rows) + " FS f=4 " + solver_name(solver) +
                 " conflicts " + std::to_string(stats.violations_before) + "->" +
                 std::to_string(stats.violations_after) + " flips " + std::to_string(stats.flips));
  state.SetItemsProcessed(state.iterations() * start.total());
}

void sizes(benchmark::internal::Benchmark* b) {
  b->Args({363, 255})->Args({2000, 2000})->Unit(benchmark::kMillisecond);
}

BENCHMARK_CAPTURE(BM_KnitDither, threshold, Dither::threshold)->Apply(sizes);
BENCHMARK_CAPTURE(BM_KnitDither, floyd_steinberg, Dither::floyd_steinberg)->Apply(sizes);
BENCHMARK_CAPTURE(BM_KnitDither, atkinson, Dither::atkinson)->Apply(sizes);
BENCHMARK_CAPTURE(BM_KnitDither, ordered, Dither::ordered)->Apply(sizes);

BENCHMARK_CAPTURE(BM_KnitSolve, random_walk, Solver::random_walk)->Apply(sizes);
BENCHMARK_CAPTURE(BM_KnitSolve, min_conflict, Solver::min_conflict)->Apply(sizes);
BENCHMARK_CAPTURE(BM_KnitSolve, gsat, Solver::gsat)->Apply(sizes);
BENCHMARK_CAPTURE(BM_KnitSolve, hybrid, Solver::hybrid)->Apply(sizes);
BENCHMARK_CAPTURE(BM_KnitSolve, texturing, Solver::texturing)->Apply(sizes);

}  // namespace
