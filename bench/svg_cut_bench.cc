// Reading and planning an SVG of many path elements (many-paths.svg ran past 90 s): read_svg
// alone, and the whole cut conversion (read, layers, plan, preview, G-code, report), at the
// reader's element limit of 100000. The label gives the input size.
#include <benchmark/benchmark.h>

#include <fstream>
#include <string>

#include "convert/common/svg_paths.h"
#include "convert/convert.h"
#include "tests/e2e/daemon_harness.h"
#include "tests/support/hostile_svg.h"

namespace {

void BM_SvgReadManyPaths(benchmark::State& state) {
  atelier::test::TempDir dir;
  const size_t n = static_cast<size_t>(state.range(0));
  const auto file = dir.path() / "many-paths.svg";
  std::ofstream(file) << atelier::testing::many_paths(n);
  size_t shapes = 0;
  for (auto _ : state) shapes = atelier::read_svg(file, 0.05).shapes.size();
  state.SetLabel(std::to_string(n) + " <path> elements, " + std::to_string(shapes) + " shapes");
}

void BM_SvgCutConvertManyPaths(benchmark::State& state) {
  atelier::test::TempDir dir;
  const size_t n = static_cast<size_t>(state.range(0));
  const auto file = dir.path() / "many-paths.svg";
  std::ofstream(file) << atelier::testing::many_paths(n);
  for (auto _ : state) {
    atelier::ConvertRequest req;
    req.kind = "cut";
    req.input = file;
    req.output_dir = dir.path() / "out";
    benchmark::DoNotOptimize(atelier::convert(req));
  }
  state.SetLabel(std::to_string(n) + " <path> elements, full cut conversion");
}

BENCHMARK(BM_SvgReadManyPaths)->Arg(10000)->Arg(99990)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_SvgCutConvertManyPaths)->Arg(10000)->Arg(99990)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
