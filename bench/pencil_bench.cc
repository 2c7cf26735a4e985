// Pencil lines (Meraj et al. 2008, issue 8 section 4): 1000 lines of 200 px in random directions
// (fixed seed), each a human_path (default PathParams: squiggle 5 px, 0.5 px spacing) drawn with
// draw_pencil_line onto one 2000 x 2000 canvas with a 6B-like profile (7 px wide), prepared once
// as a sketch job does. Target: the 1000 textured lines in < 0.2 s. BM_PencilLinePath times the
// paths alone, to show the split; BM_PencilLinesUnprepared passes the PencilProfile itself, so
// every line prepares it again (the single-line overload).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "algorithms/pencil/path.h"
#include "algorithms/pencil/profile.h"
#include "algorithms/pencil/texture.h"

namespace {

using namespace atelier::pencil;

constexpr int kLines = 1000;
constexpr double kLengthPx = 200.0;
constexpr int kCanvasPx = 2000;

// A synthetic scan of a dark, 6B-like pencil (the generator of tests/unit/pencil_texture_test.cc):
// three vertical lines ~7 px wide whose centre wanders by up to half a pixel, the centre 60..90,
// lighter by a bell-shaped fall-off towards the edges (up to ~200), with seeded grain.
cv::Mat scanned_lines(int rows, std::uint64_t seed) {
  cv::Mat img(rows, 150, CV_8UC1, cv::Scalar(255));
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> centre(60, 90);
  std::uniform_real_distribution<double> wander(-0.15, 0.15);
  std::normal_distribution<double> grain(0.0, 10.0);
  for (int cx : {25, 75, 125}) {
    double offset = 0.0;
    for (int y = 0; y < rows; ++y) {
      offset = std::clamp(offset + wander(rng), -0.5, 0.5);
      const int c = centre(rng);
      for (int x = cx - 4; x <= cx + 4; ++x) {
        const double k = x - (cx + offset);
        if (std::abs(k) > 3.5) continue;
        const double fall = 1.0 - std::exp(-(k * k) / 4.5);
        const double v = c + fall * (210 - c) + (std::abs(k) < 0.5 ? 0.0 : grain(rng));
        img.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(std::clamp(v, 0.0, 240.0));
      }
    }
  }
  return img;
}

struct Line {
  cv::Point2d from, to;
};

// kLines end-point pairs kLengthPx apart in random directions, all inside the canvas.
std::vector<Line> random_lines() {
  std::mt19937_64 rng(2008);
  std::uniform_real_distribution<double> pos(kLengthPx, kCanvasPx - kLengthPx);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI);
  std::vector<Line> lines;
  lines.reserve(kLines);
  for (int i = 0; i < kLines; ++i) {
    const cv::Point2d from(pos(rng), pos(rng));
    const double a = angle(rng);
    lines.push_back({from, from + kLengthPx * cv::Point2d(std::cos(a), std::sin(a))});
  }
  return lines;
}

// Draws the lines with `profile` (a PencilProfile or a PreparedProfile).
template <typename Profile>
void draw_lines(benchmark::State& state, const Profile& profile) {
  const std::vector<Line> lines = random_lines();
  const PathParams params;
  cv::Mat canvas(kCanvasPx, kCanvasPx, CV_8UC1);
  double px = 0;
  for (auto _ : state) {
    canvas.setTo(255);
    px = 0;
    for (int i = 0; i < kLines; ++i) {
      const std::vector<cv::Point2d> path = human_path(lines[i].from, lines[i].to, params, i).path;
      draw_pencil_line(canvas, path, profile, i);
      px += kLengthPx;
    }
    benchmark::DoNotOptimize(canvas.data);
  }
  state.SetLabel("1000 lines x 200 px, 6B-like profile (7 px wide), 2000 x 2000 canvas");
  state.counters["drawn_px"] = cv::countNonZero(canvas < 255);  // pixels marked by the last round
  state.counters["lines"] = kLines;
  state.counters["px"] = px;  // the lines' total length
  state.SetItemsProcessed(state.iterations() * kLines);
}

void BM_PencilLines(benchmark::State& state) {
  draw_lines(state, prepare(learn_profile(scanned_lines(400, 7), "6B")));
}

void BM_PencilLinesUnprepared(benchmark::State& state) {
  draw_lines(state, learn_profile(scanned_lines(400, 7), "6B"));
}

void BM_PencilLinePath(benchmark::State& state) {
  const std::vector<Line> lines = random_lines();
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
  state.counters["lines"] = kLines;
  state.counters["samples_per_line"] = static_cast<double>(samples) / kLines;
  state.SetItemsProcessed(state.iterations() * kLines);
}

BENCHMARK(BM_PencilLines)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_PencilLinesUnprepared)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_PencilLinePath)->Unit(benchmark::kMillisecond)->MinTime(1.0);

}  // namespace
