// The whole knit conversion (grid, dither, solver, metrics, pattern.png, preview.png,
// chart.pdf, knitout, report) of a tall picture at the row limit (knit::kMaxRows): 200
// stitches (the widest machine) and 1000 (the widest `width`) by 10000 rows, and shorter
// ones to show the time is linear in rows. A picture of noise: the solver's worst case.
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "convert/common/param_table.h"
#include "convert/convert.h"
#include "tests/e2e/daemon_harness.h"

namespace {

void BM_KnitConvertTall(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0)), rows = static_cast<int>(state.range(1));
  atelier::test::TempDir dir;
  // rows = width * h / w * 36 / 28 at the default gauge.
  const int h = static_cast<int>(rows * 28.0 / 36.0 + 0.5);
  cv::Mat picture(h, width, CV_8UC1);
  cv::randu(picture, 0, 256);
  const auto input = dir.path() / "tall.png";
  cv::imwrite(input.string(), picture);
  for (auto _ : state) {
    atelier::ConvertRequest req;
    req.kind = "knit";
    req.input = input;
    atelier::apply_set(req.params, "width=" + std::to_string(width));
    req.output_dir = dir.path() / "out";
    benchmark::DoNotOptimize(atelier::convert(req));
  }
  state.SetLabel(std::to_string(width) + " stitches x " + std::to_string(rows) + " rows");
}

BENCHMARK(BM_KnitConvertTall)
    ->Args({200, 2500})
    ->Args({200, 5000})
    ->Args({200, 10000})
    ->Args({1000, 10000})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace
