#include "algorithms/pencil/sketch.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "algorithms/pencil/texture.h"

namespace atelier::pencil {
namespace {

double length(const Segment& s) { return cv::norm(s.to - s.from); }

// Keeps the `n` longest of `segments` in their order (ties: the earlier).
void keep_n_longest(std::vector<Segment>* segments, std::size_t n) {
  if (segments->size() <= n) return;
  std::vector<std::size_t> order(segments->size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return length((*segments)[a]) > length((*segments)[b]);
  });
  order.resize(n);
  std::sort(order.begin(), order.end());
  std::vector<Segment> kept;
  kept.reserve(n);
  for (std::size_t i : order) kept.push_back((*segments)[i]);
  *segments = std::move(kept);
}

}  // namespace

std::uint64_t line_seed(std::uint64_t seed, std::size_t index) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (static_cast<std::uint64_t>(index) + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

std::pair<std::size_t, std::size_t> keep_longest(std::vector<Segment>* strokes,
                                                std::vector<Segment>* hatching, std::size_t max_lines) {
  keep_n_longest(strokes, max_lines);
  keep_n_longest(hatching, max_lines - strokes->size());
  return {strokes->size(), hatching->size()};
}

SketchDrawing draw_sketch(cv::Size image_size, double scale, const std::vector<Segment>& strokes,
                          const std::vector<Segment>& hatching, const PathParams& path_params,
                          const PencilProfile& profile, std::uint64_t seed,
                          const std::function<void(double)>& progress) {
  if (!(scale > 0) || !std::isfinite(scale)) throw std::invalid_argument("scale must be > 0");
  if (image_size.width <= 0 || image_size.height <= 0)
    throw std::invalid_argument("the image is empty");
  SketchDrawing d;
  const int cols = std::max(1, static_cast<int>(std::lround(image_size.width * scale)));
  const int rows = std::max(1, static_cast<int>(std::lround(image_size.height * scale)));
  d.canvas = cv::Mat(rows, cols, CV_8UC1, cv::Scalar(255));
  const std::size_t total = strokes.size() + hatching.size();
  d.lines.reserve(total);
  const std::size_t report_every = std::max<std::size_t>(1, total / 50);
  const PreparedProfile pencil = prepare(profile);  // once for all the lines
  for (std::size_t i = 0; i < total; ++i) {
    const bool hatch = i >= strokes.size();
    const Segment& s = hatch ? hatching[i - strokes.size()] : strokes[i];
    const std::uint64_t ls = line_seed(seed, i);
    HumanPath hp = human_path(s.from * scale, s.to * scale, path_params, ls);
    draw_pencil_line(d.canvas, hp.path, pencil, ls);
    d.lines.push_back({std::move(hp.path), hatch});
    if (progress && (i + 1) % report_every == 0) progress(static_cast<double>(i + 1) / total);
  }
  if (progress) progress(1.0);
  return d;
}

}  // namespace atelier::pencil
