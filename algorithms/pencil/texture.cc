#include "algorithms/pencil/texture.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>

namespace atelier::pencil {

namespace {

// Cumulative weights of `hist` over [lo, hi]; sampling falls back to uniform when it is empty.
struct RangeSampler {
  int lo = 0, hi = 0;
  std::array<double, 256> cdf{};
  double total = 0.0;

  RangeSampler(const std::vector<double>& hist, int from, int to) : lo(std::clamp(std::min(from, to), 0, 255)),
                                                                     hi(std::clamp(std::max(from, to), 0, 255)) {
    for (int v = lo; v <= hi; ++v) {
      total += hist[v];
      cdf[v - lo] = total;
    }
  }

  // A value from the quantile band [q0, q1] of the range (0 = its darkest, 1 = its lightest).
  int sample(std::mt19937_64& rng, double q0 = 0.0, double q1 = 1.0) const {
    const double u = std::uniform_real_distribution<double>(q0, q1)(rng);
    if (total <= 0.0) return lo + std::min(hi - lo, static_cast<int>(u * (hi - lo + 1)));
    const double* first = cdf.data();
    const double* it = std::upper_bound(first, first + (hi - lo + 1), u * total);
    return lo + std::min(static_cast<int>(it - first), hi - lo);
  }
};

// The along-line neighbour offset for tangent (tx, ty), encoded (dx + 1) * 3 + (dy + 1): the
// direction is turned so that it maps to +y for a vertical line (the ccm's (p, q+1)).
std::uint8_t along_code(double tx, double ty) {
  if (std::abs(ty) >= std::abs(tx) ? ty < 0 : tx < 0) {
    tx = -tx;
    ty = -ty;
  }
  const double n = std::hypot(tx, ty);
  if (n == 0.0) return 1 * 3 + 2;  // a dot: straight down
  constexpr double kSin22 = 0.3826834;  // snap to the nearest of the 8 neighbours
  const int dx = tx / n > kSin22 ? 1 : (tx / n < -kSin22 ? -1 : 0);
  const int dy = ty / n > kSin22 ? 1 : (ty / n < -kSin22 ? -1 : 0);
  return static_cast<std::uint8_t>((dx + 1) * 3 + (dy + 1));
}

}  // namespace

void draw_pencil_line(cv::Mat& canvas, const std::vector<cv::Point2d>& path, const PencilProfile& profile,
                      std::uint64_t seed) {
  if (canvas.type() != CV_8UC1) throw std::invalid_argument("draw_pencil_line: canvas must be CV_8UC1");
  if (profile.mid_hist.size() != 256 || profile.hist.size() != 256 || profile.ccm.size() != 256 * 256)
    throw std::invalid_argument("draw_pencil_line: profile needs 256-bin histograms and a 256 x 256 ccm");
  if (path.empty() || canvas.empty()) return;

  const double half = std::max(0.5, profile.width_px / 2.0);
  // The near zone is as wide as the profile's share of dark pixels ([min_range, max_mid]) asks:
  // of the ~width_px pixels across the line, that share is dark, one of them the centre.
  double dark = 0.0;
  for (int v = std::max(0, profile.min_range); v <= std::min(255, profile.max_mid); ++v) dark += profile.hist[v];
  const double inner = std::clamp(0.5 + (dark * 2.0 * half - 1.0) / 2.0, 0.5, half);
  // The region: the path's bounding box grown by the half width and the blur's reach.
  double x0 = path[0].x, x1 = x0, y0 = path[0].y, y1 = y0;
  for (const cv::Point2d& p : path) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y))
      throw std::invalid_argument("draw_pencil_line: non-finite path point");
    x0 = std::min(x0, p.x), x1 = std::max(x1, p.x);
    y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
  }
  const int margin = static_cast<int>(std::ceil(half)) + 2;
  const cv::Rect grown(static_cast<int>(std::floor(x0)) - margin, static_cast<int>(std::floor(y0)) - margin,
                       static_cast<int>(std::ceil(x1) - std::floor(x0)) + 2 * margin + 1,
                       static_cast<int>(std::ceil(y1) - std::floor(y0)) + 2 * margin + 1);
  const cv::Rect roi = grown & cv::Rect(0, 0, canvas.cols, canvas.rows);
  if (roi.empty()) return;

  // Chords of >= kChordPx between kept samples: a spline sampled every 0.5 px is smooth enough that
  // they stray from it by far less than a pixel, and the distance work below shrinks fourfold.
  constexpr double kChordPx = 2.0;
  std::vector<cv::Point2d> pts;
  pts.reserve(path.size() / 2 + 2);
  pts.push_back(path.front());
  for (std::size_t i = 1; i + 1 < path.size(); ++i)
    if (cv::norm(path[i] - pts.back()) >= kChordPx) pts.push_back(path[i]);
  if (path.size() > 1) pts.push_back(path.back());

  // Squared distance to the path and the along-line direction of the nearest segment, per pixel.
  cv::Mat dist(roi.size(), CV_32F, cv::Scalar(1e9f));
  cv::Mat along(roi.size(), CV_8U, cv::Scalar(5));
  const std::size_t segments = pts.size() == 1 ? 1 : pts.size() - 1;
  for (std::size_t s = 0; s < segments; ++s) {
    const cv::Point2d a = pts[s], b = pts[std::min(s + 1, pts.size() - 1)];
    const std::uint8_t code = along_code(b.x - a.x, b.y - a.y);
    const cv::Point2d ab = b - a;
    const double inv_len2 = ab.dot(ab) > 0.0 ? 1.0 / ab.dot(ab) : 0.0;
    const int px0 = std::max(roi.x, static_cast<int>(std::floor(std::min(a.x, b.x) - half)));
    const int px1 = std::min(roi.x + roi.width - 1, static_cast<int>(std::ceil(std::max(a.x, b.x) + half)));
    const int py0 = std::max(roi.y, static_cast<int>(std::floor(std::min(a.y, b.y) - half)));
    const int py1 = std::min(roi.y + roi.height - 1, static_cast<int>(std::ceil(std::max(a.y, b.y) + half)));
    for (int y = py0; y <= py1; ++y) {
      float* drow = dist.ptr<float>(y - roi.y);
      std::uint8_t* arow = along.ptr<std::uint8_t>(y - roi.y);
      for (int x = px0; x <= px1; ++x) {
        const double px = x - a.x, py = y - a.y;
        const double t = std::clamp((px * ab.x + py * ab.y) * inv_len2, 0.0, 1.0);
        const double ex = px - t * ab.x, ey = py - t * ab.y;
        const float d2 = static_cast<float>(ex * ex + ey * ey);
        if (d2 < drow[x - roi.x]) drow[x - roi.x] = d2, arow[x - roi.x] = code;
      }
    }
  }

  // Seed: the bell-shaped fall-off, darkest at the centre.
  std::mt19937_64 rng(seed);
  const RangeSampler centre(profile.mid_hist, profile.min_mid, profile.max_mid);
  const RangeSampler near(profile.hist, profile.min_range, profile.max_mid);
  const RangeSampler far(profile.hist, profile.max_mid, profile.max_range);
  // Within the two outer zones the fall-off continues: a pixel at fraction s of its zone's width
  // takes its value from the quantile band around s of the zone's range, so lines lighten
  // steadily outwards instead of jumping between dark and light (and the blur keeps the shades).
  // The band is about one pixel's share of its zone on each side of the line.
  auto band = [&rng](const RangeSampler& sampler, double s, double zone_px) {
    const double b = std::clamp(0.5 / std::max(zone_px, 1e-9), 0.05, 0.5);
    return sampler.sample(rng, std::clamp(s - b, 0.0, 1.0 - 2 * b), std::clamp(s + b, 2 * b, 1.0));
  };
  // line: 0 paper, 1 centre, 2 near, 3 far (the zone decides the values a pixel may take).
  cv::Mat val(roi.size(), CV_8U, cv::Scalar(255));
  cv::Mat line(roi.size(), CV_8U, cv::Scalar(0));
  std::vector<int> pixels;  // the line's pixels, y * roi.width + x in row-major order
  pixels.reserve(static_cast<std::size_t>(pts.size() * kChordPx * (2.0 * half + 2.0)) + 16);
  for (int y = 0; y < roi.height; ++y) {
    const float* drow = dist.ptr<float>(y);
    std::uint8_t* vrow = val.ptr<std::uint8_t>(y);
    std::uint8_t* lrow = line.ptr<std::uint8_t>(y);
    for (int x = 0; x < roi.width; ++x) {
      if (drow[x] > half * half) continue;
      const double d = std::sqrt(static_cast<double>(drow[x]));
      pixels.push_back(y * roi.width + x);
      if (d <= 0.5) {
        lrow[x] = 1, vrow[x] = static_cast<std::uint8_t>(centre.sample(rng));
      } else if (d <= inner) {
        lrow[x] = 2, vrow[x] = static_cast<std::uint8_t>(band(near, (d - 0.5) / std::max(1e-9, inner - 0.5), inner - 0.5));
      } else {
        lrow[x] = 3, vrow[x] = static_cast<std::uint8_t>(band(far, (d - inner) / std::max(1e-9, half - inner), half - inner));
      }
    }
  }
  const std::array<int, 4> zone_lo{0, profile.min_mid, profile.min_range, profile.max_mid};
  const std::array<int, 4> zone_hi{255, profile.max_mid, profile.max_mid, profile.max_range};

  // CCM: a pixel whose pair with its along-line neighbour never occurs in the profile takes the
  // neighbouring value (3x3) nearest its own whose pairs, forward and backward (unless that one is
  // broken anyway), occur and that lies in the pixel's own zone range (so the fall-off across the
  // line survives).
  const std::vector<double>& ccm = profile.ccm;
  auto is_line = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < roi.width && y < roi.height && line.at<std::uint8_t>(y, x) != 0;
  };
  for (int pass = 0; pass < kMaxCcmPasses; ++pass) {
    int changes = 0;
    for (const int index : pixels) {
      {
        const int y = index / roi.width, x = index % roi.width;
        const int zone = line.at<std::uint8_t>(y, x);
        const int code = along.at<std::uint8_t>(y, x);
        const int dx = code / 3 - 1, dy = code % 3 - 1;
        if (!is_line(x + dx, y + dy)) continue;
        const int v = val.at<std::uint8_t>(y, x), next = val.at<std::uint8_t>(y + dy, x + dx);
        if (ccm[v * 256 + next] > 0.0) continue;
        const bool has_prev = is_line(x - dx, y - dy);
        const int prev = has_prev ? val.at<std::uint8_t>(y - dy, x - dx) : 0;
        int best = -1, best_relaxed = -1;
        for (int ny = y - 1; ny <= y + 1; ++ny) {
          for (int nx = x - 1; nx <= x + 1; ++nx) {
            if ((nx == x && ny == y) || !is_line(nx, ny)) continue;
            const int c = val.at<std::uint8_t>(ny, nx);
            if (c < zone_lo[zone] || c > zone_hi[zone] || ccm[c * 256 + next] <= 0.0) continue;
            if (best_relaxed < 0 || std::abs(c - v) < std::abs(best_relaxed - v)) best_relaxed = c;
            if (has_prev && ccm[prev * 256 + c] <= 0.0) continue;
            if (best < 0 || std::abs(c - v) < std::abs(best - v)) best = c;
          }
        }
        // The relaxed choice only where the backward pair is broken already: a change never adds
        // a broken pair, so the passes settle instead of pushing a break up and down the line.
        const bool back_broken = has_prev && ccm[prev * 256 + v] <= 0.0;
        const int chosen = best >= 0 ? best : (back_broken || !has_prev ? best_relaxed : -1);
        if (chosen >= 0 && chosen != v) {
          val.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(chosen);
          ++changes;
        }
      }
    }
    if (changes == 0) break;
  }

  // One 3x3 Gaussian pass, then onto the canvas by min (graphite only darkens).
  cv::Mat blurred;
  cv::GaussianBlur(val, blurred, cv::Size(3, 3), kBlurSigma, kBlurSigma, cv::BORDER_REPLICATE);
  cv::Mat target = canvas(roi);
  for (const int index : pixels) {
    const int y = index / roi.width, x = index % roi.width;
    std::uint8_t& c = target.at<std::uint8_t>(y, x);
    c = std::min(c, blurred.at<std::uint8_t>(y, x));
  }
}

}  // namespace atelier::pencil
