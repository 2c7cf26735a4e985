#include "algorithms/parquetry/grid_morph.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc/edge_filter.hpp>
#include <stdexcept>
#include <string>

namespace atelier::parquetry {

namespace {

// Canny thresholds on the L2 Sobel magnitude (a black-to-white step reads 4 * 255). The
// rolling guidance output has lost its small structures, so any clear contrast left is a
// shape to follow; the finer bilateral edges must be stronger to count.
constexpr double kRgLow = 30, kRgHigh = 90;
constexpr double kFineLow = 60, kFineHigh = 150;

cv::Mat to_bgr(const cv::Mat& image) {
  if (image.empty() || image.depth() != CV_8U) {
    throw std::invalid_argument("grid morphing: the target must be a non-empty 8-bit image");
  }
  cv::Mat bgr;
  switch (image.channels()) {
    case 1: cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR); return bgr;
    case 3: return image;
    case 4: cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR); return bgr;
    default: throw std::invalid_argument("grid morphing: the target must be grey, BGR or BGRA");
  }
}

// The rolling guidance filter of Zhang et al. 2014 with sigma_space = pitch / 3. OpenCV's
// ximgproc::rollingGuidanceFilter starts its iterations from the input itself, which skips the
// paper's first step (a Gaussian that removes the small structures) and so keeps them; this
// starts from the Gaussian and rolls with ximgproc::jointBilateralFilter. It runs at a scale
// where a pitch is about 12 px: what survives the filter is larger than a patch anyway, and
// the cost no longer grows with the square of the pitch.
cv::Mat rolling_guidance(const cv::Mat& bgr, double pitch_px) {
  const double scale = std::min(1.0, 12.0 / pitch_px);
  cv::Mat small = bgr;
  if (scale < 1) cv::resize(bgr, small, cv::Size(), scale, scale, cv::INTER_AREA);
  const double sigma_space = std::max(1.0, pitch_px * scale / 3.0);
  constexpr double kSigmaColor = 25;  // grey levels: contrasts well above this are kept
  cv::Mat guide;
  cv::GaussianBlur(small, guide, cv::Size(), sigma_space);
  for (int i = 0; i < 4; ++i) {
    cv::ximgproc::jointBilateralFilter(guide, small, guide, -1, kSigmaColor, sigma_space);
  }
  if (scale < 1) cv::resize(guide, guide, bgr.size(), 0, 0, cv::INTER_LINEAR);
  return guide;
}

// Pixels of `edges` that belong to 8-connected chains of at least `min_pixels` pixels
// (Canny chains are one pixel thin, so pixels ~ length).
cv::Mat long_chains(const cv::Mat& edges, double min_pixels) {
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(edges, labels, stats, centroids, 8, CV_32S);
  std::vector<uchar> keep(static_cast<std::size_t>(n), 0);
  for (int i = 1; i < n; ++i) keep[i] = stats.at<int>(i, cv::CC_STAT_AREA) >= min_pixels ? 255 : 0;
  cv::Mat out(edges.size(), CV_8UC1);
  for (int y = 0; y < out.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    uchar* o = out.ptr<uchar>(y);
    for (int x = 0; x < out.cols; ++x) o[x] = keep[static_cast<std::size_t>(l[x])];
  }
  return out;
}

// Bilinear sample of a CV_32F map at continuous coordinates (pixel centres at +0.5), the map
// extended beyond its border by replication.
double sample(const cv::Mat& map, double x, double y) {
  const double fx = std::clamp(x - 0.5, 0.0, map.cols - 1.0);
  const double fy = std::clamp(y - 0.5, 0.0, map.rows - 1.0);
  const int x0 = std::min(static_cast<int>(fx), map.cols - 1), y0 = std::min(static_cast<int>(fy), map.rows - 1);
  const int x1 = std::min(x0 + 1, map.cols - 1), y1 = std::min(y0 + 1, map.rows - 1);
  const double ax = fx - x0, ay = fy - y0;
  const float* r0 = map.ptr<float>(y0);
  const float* r1 = map.ptr<float>(y1);
  return (1 - ay) * ((1 - ax) * r0[x0] + ax * r0[x1]) + ay * ((1 - ax) * r1[x0] + ax * r1[x1]);
}

using Quad = std::array<cv::Point2d, 4>;

// The fabricability test of one cell (corners clockwise on screen), lengths in pitches.
bool cell_ok(const Quad& q, double min_edge, double sin_min_angle) {
  for (int i = 0; i < 4; ++i) {
    const cv::Point2d a = q[i], b = q[(i + 1) % 4];
    const cv::Point2d e = b - a, f = q[(i + 2) % 4] - b;
    const double le = std::hypot(e.x, e.y), lf = std::hypot(f.x, f.y);
    if (le < min_edge || le <= 1e-12 || lf <= 1e-12) return false;
    // The turn at b is pi minus the interior angle; its sine bounds both angle limits.
    if (e.cross(f) < sin_min_angle * le * lf) return false;
    for (int k = 2; k < 4; ++k) {
      if (e.cross(q[(i + k) % 4] - a) < min_edge * le) return false;
    }
  }
  return true;
}

class Mesh {
 public:
  Mesh(int cols, int rows) : cols_(cols), rows_(rows), x_(static_cast<std::size_t>((cols + 1) * (rows + 1))) {
    for (int j = 0; j <= rows; ++j) {
      for (int i = 0; i <= cols; ++i) at(i, j) = {static_cast<double>(i), static_cast<double>(j)};
    }
  }
  cv::Point2d& at(int i, int j) { return x_[static_cast<std::size_t>(j * (cols_ + 1) + i)]; }
  const cv::Point2d& at(int i, int j) const { return x_[static_cast<std::size_t>(j * (cols_ + 1) + i)]; }
  Quad cell(int c, int r) const { return {at(c, r), at(c + 1, r), at(c + 1, r + 1), at(c, r + 1)}; }

  // The cells that have vertex (i, j) as a corner are all fine.
  bool around_ok(int i, int j, double min_edge, double sin_min_angle) const {
    for (int r = j - 1; r <= j; ++r) {
      for (int c = i - 1; c <= i; ++c) {
        if (c < 0 || r < 0 || c >= cols_ || r >= rows_) continue;
        if (!cell_ok(cell(c, r), min_edge, sin_min_angle)) return false;
      }
    }
    return true;
  }

 private:
  int cols_, rows_;
  std::vector<cv::Point2d> x_;
};

GridLines to_lines(const Mesh& mesh, int cols, int rows, double pitch) {
  GridLines out;
  out.cols = cols;
  out.rows = rows;
  out.vertical.resize(static_cast<std::size_t>(cols + 1));
  out.horizontal.resize(static_cast<std::size_t>(rows + 1));
  for (int i = 0; i <= cols; ++i) {
    for (int j = 0; j <= rows; ++j) out.vertical[i].push_back(mesh.at(i, j) * pitch);
  }
  for (int j = 0; j <= rows; ++j) {
    for (int i = 0; i <= cols; ++i) out.horizontal[j].push_back(mesh.at(i, j) * pitch);
  }
  return out;
}

GridLines solve(const cv::Mat& target, int cols, int rows, double pitch, double min_edge_px,
                const MorphSettings& s) {
  const double min_edge = min_edge_px / pitch;
  const double sin_min_angle = std::sin(s.min_angle_deg * CV_PI / 180.0);
  Mesh mesh(cols, rows);
  if (!cell_ok(mesh.cell(0, 0), min_edge, sin_min_angle)) {  // every regular cell is alike
    throw std::invalid_argument("grid morphing: the regular grid itself breaks the fabricability limits "
                                "(pitch below the minimum edge, or min_angle_deg above 90)");
  }

  // The pull is the gradient of P smoothed isotropically over 1/16 pitch (at least 1 px): a
  // pixel-thin edge's tent gets a finite slope at its ridge, and one smoothed field for both
  // components keeps the force conservative (a non-conservative pull could keep the damped mesh
  // circling forever instead of settling).
  cv::Mat potential = edge_potential(morph_edges(target, pitch, s.fine_edges), s.radius_pitches * pitch);
  cv::GaussianBlur(potential, potential, cv::Size(), std::max(1.0, pitch / 16.0));
  cv::Mat gx, gy;  // dP/dx, dP/dy in px per px, which is also (P / pitch) per pitch
  cv::Sobel(potential, gx, CV_32F, 1, 0, 3, 1.0 / 8, 0, cv::BORDER_REPLICATE);
  cv::Sobel(potential, gy, CV_32F, 0, 1, 3, 1.0 / 8, 0, cv::BORDER_REPLICATE);
  auto grad = [&](cv::Point2d u) {
    return cv::Point2d(sample(gx, u.x * pitch, u.y * pitch), sample(gy, u.x * pitch, u.y * pitch));
  };

  struct Nb { int di, dj; double rest; };
  const double d2 = std::sqrt(2.0);
  const std::array<Nb, 8> nbs{{{-1, -1, d2}, {0, -1, 1}, {1, -1, d2}, {-1, 0, 1},
                               {1, 0, 1}, {-1, 1, d2}, {0, 1, 1}, {1, 1, d2}}};
  const std::size_t n = static_cast<std::size_t>((cols + 1) * (rows + 1));
  std::vector<cv::Point2d> velocity(n), force(n);
  const double dt = s.time_step;
  for (int it = 0; it < s.iterations; ++it) {
    // Forces from the state at the start of the step (Jacobi), then moves vertex by vertex so
    // each move is checked against its neighbours' current positions.
    for (int j = 0; j <= rows; ++j) {
      for (int i = 0; i <= cols; ++i) {
        const std::size_t k = static_cast<std::size_t>(j * (cols + 1) + i);
        const cv::Point2d xi = mesh.at(i, j);
        cv::Point2d f(0, 0);
        for (const Nb& nb : nbs) {
          const int a = i + nb.di, b = j + nb.dj;
          if (a < 0 || b < 0 || a > cols || b > rows) continue;
          const cv::Point2d d = mesh.at(a, b) - xi;
          const double len = std::hypot(d.x, d.y);
          if (len > 1e-12) f += d * (s.spring * (len - nb.rest) / len);
        }
        force[k] = f - velocity[k] * s.damping - grad(xi) * s.edge_weight;
      }
    }
    double max_move = 0;
    for (int j = 0; j <= rows; ++j) {
      for (int i = 0; i <= cols; ++i) {
        const bool x_fixed = i == 0 || i == cols, y_fixed = j == 0 || j == rows;
        if (x_fixed && y_fixed) continue;  // corners
        const std::size_t k = static_cast<std::size_t>(j * (cols + 1) + i);
        cv::Point2d v = velocity[k] + force[k] * dt;
        if (x_fixed) v.x = 0;  // left / right border vertices slide vertically
        if (y_fixed) v.y = 0;
        const cv::Point2d step = v * dt;
        if (step.x == 0 && step.y == 0) {
          velocity[k] = v;
          continue;
        }
        const cv::Point2d old = mesh.at(i, j);
        double t = 1.0;
        // Projection onto the fabricable set: shorten the move until every cell around is
        // fine; t = 0 is always fine because the state before the move was.
        for (; t > 1.0 / 64; t *= 0.5) {
          mesh.at(i, j) = old + step * t;
          if (mesh.around_ok(i, j, min_edge, sin_min_angle)) break;
        }
        if (t <= 1.0 / 64) {
          t = 0;
          mesh.at(i, j) = old;
        }
        velocity[k] = t < 1.0 ? cv::Point2d(0, 0) : v;  // a blocked vertex stops (inelastic)
        max_move = std::max(max_move, t * std::hypot(step.x, step.y));
      }
    }
    if (max_move < 1e-6) break;
  }
  return to_lines(mesh, cols, rows, pitch);
}

}  // namespace

cv::Mat morph_edges(const cv::Mat& target, double pitch_px, bool fine_edges) {
  if (!(pitch_px > 0)) throw std::invalid_argument("grid morphing: pitch must be positive");
  try {
    const cv::Mat bgr = to_bgr(target);
    cv::Mat e_rg;
    cv::Canny(rolling_guidance(bgr, pitch_px), e_rg, kRgLow, kRgHigh, 3, true);
    if (!fine_edges) return e_rg;
    cv::Mat smooth, e_fine;
    cv::bilateralFilter(bgr, smooth, -1, 30.0, std::max(1.0, pitch_px / 10.0));
    cv::Canny(smooth, e_fine, kFineLow, kFineHigh, 3, true);
    cv::Mat edges;
    cv::max(e_rg, long_chains(e_fine, pitch_px), edges);
    return edges;
  } catch (const cv::Exception& e) {
    throw std::runtime_error(std::string("grid morphing: edge detection failed: ") + e.what());
  }
}

cv::Mat edge_potential(const cv::Mat& edges, double radius_px) {
  if (edges.empty() || edges.type() != CV_8UC1) {
    throw std::invalid_argument("edge potential: edges must be a non-empty CV_8UC1 image");
  }
  if (!(radius_px > 0)) throw std::invalid_argument("edge potential: radius must be positive");
  if (cv::countNonZero(edges) == 0) return cv::Mat::zeros(edges.size(), CV_32F);
  cv::Mat background = edges == 0, dist;
  cv::distanceTransform(background, dist, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  const cv::Mat beyond = radius_px - dist;
  cv::Mat potential = cv::min(dist, beyond);
  return cv::max(potential, 0.0);
}

GridLines morph_grid(const cv::Mat& target, int cols, int rows, double pitch_px, double min_edge_px,
                     const MorphSettings& settings) {
  if (cols < 1 || rows < 1) throw std::invalid_argument("grid morphing: the grid needs at least one cell");
  if (!(pitch_px > 0) || !(min_edge_px >= 0)) {
    throw std::invalid_argument("grid morphing: pitch must be positive and the minimum edge not negative");
  }
  if (!(settings.time_step > 0) || settings.iterations < 0 || !(settings.radius_pitches > 0)) {
    throw std::invalid_argument("grid morphing: bad solver settings");
  }
  try {
    return solve(target, cols, rows, pitch_px, min_edge_px, settings);
  } catch (const cv::Exception& e) {
    throw std::runtime_error(std::string("grid morphing failed: ") + e.what());
  }
}

}  // namespace atelier::parquetry
