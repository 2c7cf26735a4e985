// Pencil lines (Meraj et al. 2008; issue 8 section 4, target: 1000 textured lines of 200 px in
// under 0.2 s). Input: 1000 end-point pairs 200 px apart in random directions (fixed seed) inside
// a 2000 x 2000 drawing; default PathParams (squiggle 5 px, 0.5 px spacing); the shipped HB (the
// default pencil, 4.3 px wide) and 6B (7 px wide) profiles.
//   BM_PencilLinePath          the paths alone (minimum jerk, squiggle, Catmull-Rom)
//   BM_PencilLines/P           path + texture, one canvas, the profile prepared once, 1 thread
//   BM_PencilLinesUnprepared   the same through the single-line overload (prepares every line)
//   BM_Sketch1000Lines/P/T     as a sketch job draws them (draw_sketch) on T threads
// P: 0 = HB, 1 = 6B.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "algorithms/pencil/path.h"
#include "algorithms/pencil/sketch.h"
#include "algorithms/pencil/texture.h"
#include "convert/sketch/pencil_profile_file.h"

namespace {

using namespace atelier::pencil;

constexpr int kLines = 1000;
constexpr double kLengthPx = 200.0;
constexpr int kCanvasPx = 2000;

std::vector<Segment> random_lines() {
  std::mt19937_64 rng(2008);
  std::uniform_real_distribution<double> pos(kLengthPx, kCanvasPx - kLengthPx);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI);
  std::vector<Segment> lines;
  lines.reserve(kLines);
  for (int i = 0; i < kLines; ++i) {
    const cv::Point2d from(pos(rng), pos(rng));
    const double a = angle(rng);
    lines.push_back({from, from + kLengthPx * cv::Point2d(std::cos(a), std::sin(a))});
  }
  return lines;
}

PencilProfile pencil(int64_t which) { return atelier::shipped_pencil(which == 0 ? "HB" : "6B"); }

void label(benchmark::State& state, const std::string& pencil_name, const std::string& more = "") {
  state.SetLabel("1000 lines x 200 px, " + pencil_name + ", 2000 x 2000" + more);
  state.counters["lines/s"] = benchmark::Counter(double(kLines) * state.iterations(), benchmark::Counter::kIsRate);
}

// Draws the lines with `profile` (a PencilProfile or a PreparedProfile) onto one canvas.
template <typename Profile>
void draw_lines(benchmark::State& state, const Profile& profile) {
  const std::vector<Segment> lines = random_lines();
  const PathParams params;
  cv::Mat canvas(kCanvasPx, kCanvasPx, CV_8UC1);
  for (auto _ : state) {
    canvas.setTo(255);
    for (int i = 0; i < kLines; ++i)
      draw_pencil_line(canvas, human_path(lines[i].from, lines[i].to, params, i).path, profile, i);
    benchmark::DoNotOptimize(canvas.data);
  }
  state.counters["drawn_px"] = cv::countNonZero(canvas < 255);  // pixels marked by the last round
}

void BM_PencilLines(benchmark::State& state) {
  const PencilProfile p = pencil(state.range(0));
  draw_lines(state, prepare(p));
  label(state, p.name);
}

void BM_PencilLinesUnprepared(benchmark::State& state) {
  const PencilProfile p = pencil(state.range(0));
  draw_lines(state, p);
  label(state, p.name, ", prepared per line");
}

void BM_PencilLinePath(benchmark::State& state) {
  const std::vector<Segment> lines = random_lines();
  const PathParams params;
  std::size_t samples = 0;
  for (auto _ : state) {
    samples = 0;
    for (int i = 0; i < kLines; ++i) {
      const std::vector<cv::Point2d> path = human_path(lines[i].from, lines[i].to, params, i).path;
      samples += path.size();
      benchmark::DoNotOptimize(path.data());
    }
  }
  state.SetLabel("1000 paths x 200 px (no texture)");
  state.counters["samples_per_line"] = static_cast<double>(samples) / kLines;
}

void BM_Sketch1000Lines(benchmark::State& state) {
  const PencilProfile p = pencil(state.range(0));
  const std::vector<Segment> lines = random_lines();
  const int threads = static_cast<int>(state.range(1));
  for (auto _ : state) {
    SketchDrawing d = draw_sketch({kCanvasPx, kCanvasPx}, 1.0, lines, {}, {}, p, 7, {}, threads);
    benchmark::DoNotOptimize(d.canvas.data);
  }
  label(state, p.name, ", draw_sketch on " + std::to_string(threads) + " thread(s)");
}

BENCHMARK(BM_PencilLinePath)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK(BM_PencilLines)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK(BM_PencilLinesUnprepared)->Arg(1)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK(BM_Sketch1000Lines)->Args({0, 1})->Args({0, 2})->Args({1, 1})->Args({1, 2})
    ->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

}  // namespace
