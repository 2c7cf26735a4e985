// Parquetry matching benchmark (issue 5): the paper's eye-sized result, 28x17 patches of 14 mm
// with 15 rotations over the 12 real wood scans (read at 25.4 dpi: 0.34 m^2 of veneer), and
// smaller/larger cases to show cost against patches x wood area. Target: under 10 s on 2 cores.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <fstream>
#include <string>
#include <sys/resource.h>

#include "algorithms/parquetry/plan.h"

namespace {

using namespace atelier::parquetry;

std::vector<Sheet> wood(int count, double dpi = 25.4) {
  const std::filesystem::path dir =
      std::filesystem::path(ATELIER_TEST_DATA) / "wood";
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    if (e.path().extension() == ".png") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  if (files.size() < static_cast<std::size_t>(count)) {
    throw std::runtime_error("parquetry_bench: not enough wood scans in " + dir.string());
  }
  std::vector<Sheet> sheets;
  for (int i = 0; i < count; ++i) {
    Sheet s{files[i].stem().string(), cv::imread(files[i].string(), cv::IMREAD_COLOR), {}, dpi};
    sheets.push_back(s);
  }
  return sheets;
}

// butterfly.jpg resized to cols:rows, so the result is exactly cols x rows patches.
cv::Mat target(int cols, int rows) {
  const std::string path = std::string(ATELIER_TEST_DATA) + "/butterfly.jpg";
  cv::Mat m = cv::imread(path, cv::IMREAD_COLOR);
  if (m.empty()) throw std::runtime_error("parquetry_bench: cannot read " + path);
  cv::resize(m, m, cv::Size(cols * 20, rows * 20), 0, 0, cv::INTER_AREA);
  return m;
}

// Args: patch columns, patch rows, sheets, rotations, shapes (0 regular, 1 morphed, 2 dp).
void BM_ParquetryPlan(benchmark::State& state) {
  const int cols = static_cast<int>(state.range(0)), rows = static_cast<int>(state.range(1));
  const auto sheets = wood(static_cast<int>(state.range(2)));
  const cv::Mat photo = target(cols, rows);
  Params p;
  p.rotations = static_cast<int>(state.range(3));
  p.size_mm = std::min(cols, rows) * p.patch_mm;
  const int shapes = state.range(4);
  if (shapes == 1) p.grid = Grid::morphed;
  if (shapes == 2) p.refine = Refine::dp;
  double area = 0;
  for (const Sheet& s : sheets) area += s.image.cols * s.image.rows;  // 1 px = 1 mm^2
  std::size_t pieces = 0;
  double seconds = 0;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const Plan plan = make_plan(photo, sheets, Stock{}, p);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    pieces = plan.pieces.size();
    benchmark::DoNotOptimize(plan.error);
  }
  state.SetLabel(std::to_string(cols) + "x" + std::to_string(rows) + " patches of 14 mm, " +
                 std::to_string(p.rotations) + " rotations, " + std::to_string(sheets.size()) +
                 " sheets (" + std::to_string(area / 1e6).substr(0, 4) + " m^2) at " +
                 std::to_string(p.px_per_mm).substr(0, 4) + " px/mm, " + grid_name(p.grid) + "/" + refine_name(p.refine) + ", " +
                 std::to_string(cv::getNumThreads()) + " threads");
  state.counters["pieces"] = static_cast<double>(pieces);
  state.counters["ms_per_patch"] =
      1000.0 * seconds / static_cast<double>(state.iterations()) / static_cast<double>(pieces);
}
BENCHMARK(BM_ParquetryPlan)
    ->Args({28, 17, 12, 15, 0})  // the target
    ->Args({14, 9, 12, 15, 0})   // a quarter of the patches
    ->Args({14, 9, 6, 15, 0})    // and half the wood
    ->Args({28, 17, 12, 15, 1})  // the target on a morphed grid
    ->Args({28, 17, 12, 15, 2})  // dp cuts: the regular grid's cores, then the seams
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(1);

// Peak RSS of what runs after reset_peak(): /proc/self/clear_refs "5" resets VmHWM (Linux);
// when it cannot be written, getrusage's maximum since the process started.
bool reset_peak() {
  std::ofstream f("/proc/self/clear_refs");
  return static_cast<bool>(f << "5") && static_cast<bool>(f.flush());
}
double peak_rss_mb() {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024;  // kB
  }
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024;
}

// The WoodPixel setting of issue 23 on one input: butterfly.jpg as 12 x 16 = 192 pieces of
// 9.144 mm, 12 wood scans read at 50 dpi (1.9685 px/mm, the working resolution too), 15
// rotations, w_intens = w_edge = w_hist = 0.5, saliency order. Arg: 0 regular, 1 dp, 2 morphed.
// Counters: seconds, peak RSS of this plan (MB), pieces, blurred SSIM (Plan::ssim).
void BM_ParquetryWoodPixel(benchmark::State& state) {
  const auto sheets = wood(12, 50.0);
  const std::string path = std::string(ATELIER_TEST_DATA) + "/butterfly.jpg";
  const cv::Mat photo = cv::imread(path, cv::IMREAD_COLOR);
  if (photo.empty()) throw std::runtime_error("parquetry_bench: cannot read " + path);
  Params p;
  p.patch_mm = 9.144;
  p.px_per_mm = 1.9685;
  p.size_mm = 12 * p.patch_mm;
  p.rotations = 15;
  const int shapes = static_cast<int>(state.range(0));
  if (shapes == 1) p.refine = Refine::dp;
  if (shapes == 2) p.grid = Grid::morphed;
  double seconds = 0, peak = 0, ssim = 0, pieces = 0;
  bool reset = true;
  std::string failed;
  for (auto _ : state) {
    reset = reset_peak() && reset;
    const auto start = std::chrono::steady_clock::now();
    try {
      const Plan plan = make_plan(photo, sheets, Stock{}, p);
      pieces = static_cast<double>(plan.pieces.size());
      ssim = plan.ssim;
    } catch (const Unfabricable& e) {
      failed = e.what();  // the memory and time figures still hold
    }
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    peak = std::max(peak, peak_rss_mb());
  }
  state.SetLabel(std::string("butterfly 192 x 9.144 mm, 12 sheets at 50 dpi, 15 rotations, 1.97 px/mm, ") +
                 grid_name(p.grid) + "/" + refine_name(p.refine) +
                 (reset ? "" : ", peak RSS since start (clear_refs not writable)") +
                 (failed.empty() ? "" : ", NOT FABRICABLE: " + failed));
  state.counters["seconds"] = seconds / static_cast<double>(state.iterations());
  state.counters["peak_rss_mb"] = peak;
  state.counters["pieces"] = pieces;
  state.counters["ssim"] = ssim;
}
BENCHMARK(BM_ParquetryWoodPixel)
    ->Arg(0)  // regular
    ->Arg(1)  // dp
    ->Arg(2)  // morphed
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(1);

}  // namespace
