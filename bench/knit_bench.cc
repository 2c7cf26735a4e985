// Knit benchmarks: every dither and every solver on grids made from a real painting
// (tests/data/starry_night.jpg) at the paper's 363x255 and at 2000x2000; and BM_KnitJob, the
// whole knit job (issue 22's 364x351 stitches from pic1.png, defaults incl. dither and solver
// "auto") writing every output to a temporary folder.
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
#include "convert/common/param_table.h"
#include "convert/convert.h"
#include "tests/e2e/daemon_harness.h"

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
BENCHMARK_CAPTURE(BM_KnitSolve, hybrid_texturing, Solver::hybrid_texturing)->Apply(sizes);

// The whole job as atelierd runs it: load, grid, auto search, metrics, pattern.png,
// preview.png, chart.pdf, pattern.k, report.json. Label: the report's per-stage times.
void BM_KnitJob(benchmark::State& state) {
  atelier::test::TempDir tmp;
  atelier::ConvertRequest req;
  req.kind = "knit";
  req.input = std::string(ATELIER_TEST_DATA) + "/pic1.png";  // 400x300 -> 364x351 stitches
  atelier::apply_set(req.params, "width=364");
  req.output_dir = tmp.path() / "out";
  atelier::ConvertResult result;
  for (auto _ : state) result = atelier::convert(req);
  std::string label = std::to_string(result.report["grid"]["stitches"].get<int>()) + "x" +
                      std::to_string(result.report["grid"]["rows"].get<int>());
  for (const auto& [stage, ms] : result.report["timings_ms"].items())
    label += " " + stage + "=" + std::to_string(static_cast<int>(ms.get<double>() + 0.5));
  state.SetLabel(label);
}
BENCHMARK(BM_KnitJob)->Unit(benchmark::kMillisecond)->MinTime(2.0);

}  // namespace
