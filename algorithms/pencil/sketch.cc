#include "algorithms/pencil/sketch.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <mutex>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <thread>

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

// The drawn path as kept for the SVG and the engraving, thinned by Douglas-Peucker to within
// kKeptTolerancePx: the spline is sampled every 0.5 px, many times the points its shape needs
// (a 40 Mpx image's hatching held 118 M points). The ends stay exact.
constexpr double kKeptTolerancePx = 0.05;
std::vector<cv::Point2d> thinned(const std::vector<cv::Point2d>& path) {
  if (path.size() <= 2) return path;
  std::vector<cv::Point2f> in(path.begin(), path.end()), out;
  cv::approxPolyDP(in, out, kKeptTolerancePx, false);
  std::vector<cv::Point2d> kept(out.begin(), out.end());
  kept.front() = path.front();
  kept.back() = path.back();
  return kept;
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
                          const std::function<void(double)>& progress, int threads) {
  if (!(scale > 0) || !std::isfinite(scale)) throw std::invalid_argument("scale must be > 0");
  if (image_size.width <= 0 || image_size.height <= 0)
    throw std::invalid_argument("the image is empty");
  if (threads < 1) throw std::invalid_argument("threads must be >= 1");
  const int cols = std::max(1, static_cast<int>(std::lround(image_size.width * scale)));
  const int rows = std::max(1, static_cast<int>(std::lround(image_size.height * scale)));
  const std::size_t total = strokes.size() + hatching.size();
  const PreparedProfile pencil = prepare(profile);  // once for all the lines

  SketchDrawing d;
  d.lines.resize(total);
  // Thread t draws lines [begin(t), begin(t + 1)) onto canvases[t]; the caller's thread is t = 0.
  const std::size_t workers = std::max<std::size_t>(1, std::min<std::size_t>(threads, total));
  auto begin = [&](std::size_t t) { return total * t / workers; };
  std::vector<cv::Mat> canvases(workers);
  std::atomic<std::size_t> done{0};
  auto draw_line = [&](std::size_t i, cv::Mat& canvas) {
    const bool hatch = i >= strokes.size();
    const Segment& s = hatch ? hatching[i - strokes.size()] : strokes[i];
    const std::uint64_t ls = line_seed(seed, i);
    HumanPath hp = human_path(s.from * scale, s.to * scale, path_params, ls);
    draw_pencil_line(canvas, hp.path, pencil, ls);
    d.lines[i] = {thinned(hp.path), hatch};
    return done.fetch_add(1, std::memory_order_relaxed) + 1;
  };
  std::vector<std::thread> pool;
  std::exception_ptr failure;
  std::mutex failure_mutex;
  for (std::size_t t = 1; t < workers; ++t)
    pool.emplace_back([&, t] {
      try {
        canvases[t] = cv::Mat(rows, cols, CV_8UC1, cv::Scalar(255));
        for (std::size_t i = begin(t); i < begin(t + 1); ++i) draw_line(i, canvases[t]);
      } catch (...) {
        std::lock_guard<std::mutex> lock(failure_mutex);
        if (!failure) failure = std::current_exception();
      }
    });
  try {
    // The caller's run; progress is reported between its lines (callbacks stay on this thread).
    canvases[0] = cv::Mat(rows, cols, CV_8UC1, cv::Scalar(255));
    const std::size_t report_every = std::max<std::size_t>(1, total / 50);
    for (std::size_t i = begin(0); i < begin(1); ++i) {
      const std::size_t n = draw_line(i, canvases[0]);
      if (progress && (i + 1) % report_every == 0) progress(static_cast<double>(n) / total);
    }
  } catch (...) {
    for (auto& th : pool) th.join();
    throw;
  }
  for (auto& th : pool) th.join();
  if (failure) std::rethrow_exception(failure);
  d.canvas = canvases[0];
  for (std::size_t t = 1; t < workers; ++t) cv::min(d.canvas, canvases[t], d.canvas);
  if (progress) progress(1.0);
  return d;
}

}  // namespace atelier::pencil
