#include "algorithms/knit/dither.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <vector>

namespace atelier::knit {
namespace {

void check_gray(const cv::Mat& gray, const char* who) {
  if (gray.empty()) throw std::invalid_argument(std::string(who) + ": the grey image is empty");
  if (gray.type() != CV_8UC1)
    throw std::invalid_argument(std::string(who) + ": the grey image must be CV_8UC1");
}

cv::Mat threshold_grid(const cv::Mat& gray, int threshold) {
  cv::Mat grid(gray.size(), CV_8UC1);
  for (int y = 0; y < gray.rows; ++y) {
    const uint8_t* g = gray.ptr<uint8_t>(y);
    uint8_t* o = grid.ptr<uint8_t>(y);
    for (int x = 0; x < gray.cols; ++x) o[x] = g[x] < threshold ? 1 : 0;
  }
  return grid;
}

// One error-diffusion tap: share of the error sent to (dx, dy).
struct Tap {
  int dx, dy;
  float weight;
};

// Error diffusion in raster order. Dark (1) when the corrected level is below `threshold`;
// the quantisation error (level minus 0 or 255) is spread over the taps.
cv::Mat diffuse(const cv::Mat& gray, int threshold, const std::vector<Tap>& taps, int max_dy) {
  const int w = gray.cols, h = gray.rows, pad = 2;
  // Error rows with `pad` columns of slack each side so taps need no bounds checks.
  std::vector<std::vector<float>> err(max_dy + 1, std::vector<float>(w + 2 * pad, 0.f));
  cv::Mat grid(gray.size(), CV_8UC1);
  for (int y = 0; y < h; ++y) {
    const uint8_t* g = gray.ptr<uint8_t>(y);
    uint8_t* o = grid.ptr<uint8_t>(y);
    std::vector<float>& cur = err[0];
    for (int x = 0; x < w; ++x) {
      const float level = g[x] + cur[x + pad];
      const bool dark = level < threshold;
      o[x] = dark ? 1 : 0;
      const float e = level - (dark ? 0.f : 255.f);
      for (const Tap& t : taps) err[t.dy][x + pad + t.dx] += e * t.weight;
    }
    std::rotate(err.begin(), err.begin() + 1, err.end());
    std::fill(err.back().begin(), err.back().end(), 0.f);
  }
  return grid;
}

cv::Mat ordered(const cv::Mat& gray, int threshold) {
  static const int bayer[8][8] = {
      {0, 32, 8, 40, 2, 34, 10, 42},  {48, 16, 56, 24, 50, 18, 58, 26},
      {12, 44, 4, 36, 14, 46, 6, 38}, {60, 28, 52, 20, 62, 30, 54, 22},
      {3, 35, 11, 43, 1, 33, 9, 41},  {51, 19, 59, 27, 49, 17, 57, 25},
      {15, 47, 7, 39, 13, 45, 5, 37}, {63, 31, 55, 23, 61, 29, 53, 21}};
  // Cell thresholds 2, 6, .., 254 so a uniform grey g gets about (255 - g) / 255 dark
  // stitches; `threshold` shifts them (128 = neutral) like a brightness control.
  const int shift = threshold - 128;
  cv::Mat grid(gray.size(), CV_8UC1);
  for (int y = 0; y < gray.rows; ++y) {
    const uint8_t* g = gray.ptr<uint8_t>(y);
    uint8_t* o = grid.ptr<uint8_t>(y);
    const int* b = bayer[y & 7];
    for (int x = 0; x < gray.cols; ++x) o[x] = g[x] < b[x & 7] * 4 + 2 + shift ? 1 : 0;
  }
  return grid;
}

}  // namespace

Dither dither_from_name(const std::string& name) {
  if (name == "threshold") return Dither::threshold;
  if (name == "floyd-steinberg") return Dither::floyd_steinberg;
  if (name == "atkinson") return Dither::atkinson;
  if (name == "ordered") return Dither::ordered;
  if (name == "auto") return Dither::automatic;
  throw std::invalid_argument("unknown dither \"" + name +
                              "\" (threshold, floyd-steinberg, atkinson, ordered, auto)");
}

std::string dither_name(Dither d) {
  switch (d) {
    case Dither::threshold: return "threshold";
    case Dither::floyd_steinberg: return "floyd-steinberg";
    case Dither::atkinson: return "atkinson";
    case Dither::ordered: return "ordered";
    case Dither::automatic: return "auto";
  }
  throw std::invalid_argument("dither_name: invalid Dither value");
}

bool looks_like_line_drawing(const cv::Mat& gray) {
  check_gray(gray, "looks_like_line_drawing");
  // A drawing or logo puts most pixels on a few flat grey levels (paper, ink, fills) and
  // changes tone only at sharp edges; a photograph or painting spreads over many levels
  // and is full of soft gradients.
  int hist[256] = {0};
  for (int y = 0; y < gray.rows; ++y) {
    const uint8_t* g = gray.ptr<uint8_t>(y);
    for (int x = 0; x < gray.cols; ++x) ++hist[g[x]];
  }
  const double n = static_cast<double>(gray.total());
  // Share of the pixels within +-6 levels of the three strongest grey levels.
  double in_peaks = 0;
  for (int k = 0; k < 3; ++k) {
    int best = 0;
    long best_mass = -1;
    for (int v = 0; v < 256; ++v) {
      long mass = 0;
      for (int u = std::max(0, v - 6); u <= std::min(255, v + 6); ++u) mass += hist[u];
      if (mass > best_mass) best_mass = mass, best = v;
    }
    in_peaks += best_mass;
    for (int u = std::max(0, best - 6); u <= std::min(255, best + 6); ++u) hist[u] = 0;
  }
  // Share of the pixels on a soft gradient (neither flat nor a sharp edge).
  cv::Mat gx, gy, mag;
  cv::Sobel(gray, gx, CV_32F, 1, 0);
  cv::Sobel(gray, gy, CV_32F, 0, 1);
  cv::magnitude(gx, gy, mag);
  const double soft = (cv::countNonZero(mag >= 8) - cv::countNonZero(mag > 100)) / n;
  return in_peaks / n >= 0.6 && soft <= 0.25;
}

Dither resolve_dither(Dither d, const cv::Mat& gray) {
  if (d != Dither::automatic) return d;
  return looks_like_line_drawing(gray) ? Dither::threshold : Dither::floyd_steinberg;
}

cv::Mat dither(const cv::Mat& gray, Dither method, int threshold) {
  check_gray(gray, "dither");
  if (threshold < 0 || threshold > 255)
    throw std::invalid_argument("dither: threshold must be within 0..255, got " +
                                std::to_string(threshold));
  switch (method) {
    case Dither::threshold:
      return threshold_grid(gray, threshold);
    case Dither::floyd_steinberg:
      return diffuse(gray, threshold,
                     {{1, 0, 7.f / 16}, {-1, 1, 3.f / 16}, {0, 1, 5.f / 16}, {1, 1, 1.f / 16}}, 1);
    case Dither::atkinson:
      // Atkinson passes on only 6/8 of the error, which keeps highlights and shadows clean.
      return diffuse(gray, threshold,
                     {{1, 0, 1.f / 8}, {2, 0, 1.f / 8}, {-1, 1, 1.f / 8}, {0, 1, 1.f / 8},
                      {1, 1, 1.f / 8}, {0, 2, 1.f / 8}},
                     2);
    case Dither::ordered:
      return ordered(gray, threshold);
    case Dither::automatic:
      throw std::invalid_argument("dither: resolve \"auto\" with resolve_dither() first");
  }
  throw std::invalid_argument("dither: invalid Dither value");
}

}  // namespace atelier::knit
