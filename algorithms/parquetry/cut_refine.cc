#include "algorithms/parquetry/cut_refine.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace atelier::parquetry {

namespace {

void check(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("refine_seams: " + what);
}

void validate(const SeamInput& in) {
  check(in.cols >= 1 && in.rows >= 1, "needs at least one cell");
  check(in.half >= 1 && 2 * in.half < in.pitch, "needs 1 <= half < pitch / 2");
  const cv::Size size(in.cols * in.pitch, in.rows * in.pitch);
  check(in.target_f1.type() == CV_32F && in.target_f1.size() == size &&
            in.target_f2.type() == CV_32F && in.target_f2.size() == size,
        "target features must be CV_32F of the result size");
  const std::size_t n = static_cast<std::size_t>(in.cols * in.rows);
  check(in.wood_f1.size() == n && in.wood_f2.size() == n, "needs wood features for every cell");
  check(in.available.empty() || in.available.size() == n, "needs the available wood of every cell");
  for (int r = 0; r < in.rows; ++r) {
    for (int c = 0; c < in.cols; ++c) {
      const std::size_t k = static_cast<std::size_t>(r * in.cols + c);
      const cv::Size s = cell_window(in, c, r).size();
      check(in.wood_f1[k].type() == CV_32F && in.wood_f1[k].size() == s &&
                in.wood_f2[k].type() == CV_32F && in.wood_f2[k].size() == s,
            "wood features of cell (" + std::to_string(c) + ", " + std::to_string(r) +
                ") must be CV_32F over its window");
      check(in.available.empty() || (in.available[k].type() == CV_8UC1 && in.available[k].size() == s),
            "available wood of cell (" + std::to_string(c) + ", " + std::to_string(r) +
                ") must be CV_8UC1 over its window");
    }
  }
}

// Eq. 8 per pixel: squared feature difference between a cell's wood and the target; a pixel
// the cell's wood cannot give costs more than any cut could save.
constexpr double kUnavailable = 1e15;

class PixelError {
 public:
  explicit PixelError(const SeamInput& in) : in_(in) {
    for (int r = 0; r < in.rows; ++r) {
      for (int c = 0; c < in.cols; ++c) win_.push_back(cell_window(in, c, r));
    }
  }
  double operator()(int cell, int x, int y) const {
    const cv::Rect& w = win_[static_cast<std::size_t>(cell)];
    // The band limits guarantee this; a violation is a bug here, not bad input.
    if (!w.contains({x, y})) {
      throw std::logic_error("refine_seams: pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                             ") given to cell " + std::to_string(cell) + " outside its window");
    }
    const std::size_t k = static_cast<std::size_t>(cell);
    if (!in_.available.empty() && !in_.available[k].at<uchar>(y - w.y, x - w.x)) return kUnavailable;
    const double d1 = in_.wood_f1[k].at<float>(y - w.y, x - w.x) - in_.target_f1.at<float>(y, x);
    const double d2 = in_.wood_f2[k].at<float>(y - w.y, x - w.x) - in_.target_f2.at<float>(y, x);
    return d1 * d1 + d2 * d2;
  }

 private:
  const SeamInput& in_;
  std::vector<cv::Rect> win_;
};


// Minimum-cost path through an n x m cost table (row k: the cost of each of m positions at
// step k), moving at most one position per step, and not at all into steps with
// may_move[k] == 0. Returns the positions and the path's cost.
std::vector<int> best_path(const std::vector<double>& cost, int n, int m,
                           const std::vector<char>& may_move, double& total) {
  std::vector<double> acc(cost.begin(), cost.begin() + m);
  std::vector<int> from(static_cast<std::size_t>(n * m), 0);
  std::vector<double> next(static_cast<std::size_t>(m));
  for (int k = 1; k < n; ++k) {
    for (int p = 0; p < m; ++p) {
      int q_best = p;  // staying wins ties: straighter cuts
      if (may_move[static_cast<std::size_t>(k)]) {
        for (int q = std::max(0, p - 1); q <= std::min(m - 1, p + 1); ++q) {
          if (acc[static_cast<std::size_t>(q)] < acc[static_cast<std::size_t>(q_best)]) q_best = q;
        }
      }
      from[static_cast<std::size_t>(k * m + p)] = q_best;
      next[static_cast<std::size_t>(p)] = acc[static_cast<std::size_t>(q_best)] + cost[static_cast<std::size_t>(k * m + p)];
    }
    acc.swap(next);
  }
  int p = m / 2;  // the grid line wins ties
  for (int q = 0; q < m; ++q) {
    if (acc[static_cast<std::size_t>(q)] < acc[static_cast<std::size_t>(p)] ||
        (acc[static_cast<std::size_t>(q)] == acc[static_cast<std::size_t>(p)] &&
         std::abs(q - m / 2) < std::abs(p - m / 2))) {
      p = q;
    }
  }
  total = acc[static_cast<std::size_t>(p)];
  std::vector<int> path(static_cast<std::size_t>(n));
  for (int k = n - 1; k >= 0; --k) {
    path[static_cast<std::size_t>(k)] = p;
    p = from[static_cast<std::size_t>(k * m + p)];
  }
  return path;
}

// Eq. 9 for one cut: along its length (rows for a vertical cut), the cost of every position in
// its band, the pixels before the cut taken from the cell before it. `cell_before(x, y)`
// resolves the other direction's cut. Replaces `cut` by the optimum if that is cheaper.
template <typename CellAt>
void refine_cut(std::vector<int>& cut, int line, int pitch, int half, const std::vector<char>& may_move,
                CellAt cell_at) {
  const int n = static_cast<int>(cut.size()), m = 2 * half + 1, lo = line * pitch - half;
  std::vector<double> cost(static_cast<std::size_t>(n * m));
  std::vector<double> before(static_cast<std::size_t>(m)), after(static_cast<std::size_t>(m));
  for (int k = 0; k < n; ++k) {
    // before[p]: band pixels [lo, lo + p) in the cell before the cut; after[p]: [lo + p, lo + 2 half).
    before[0] = 0;
    for (int p = 1; p < m; ++p) before[p] = before[p - 1] + cell_at(line - 1, lo + p - 1, k);
    after[m - 1] = 0;
    for (int p = m - 2; p >= 0; --p) after[p] = after[p + 1] + cell_at(line, lo + p, k);
    for (int p = 0; p < m; ++p) cost[static_cast<std::size_t>(k * m + p)] = before[p] + after[p];
  }
  double best = 0;
  const std::vector<int> path = best_path(cost, n, m, may_move, best);
  double current = 0;
  for (int k = 0; k < n; ++k) current += cost[static_cast<std::size_t>(k * m + cut[static_cast<std::size_t>(k)] - lo)];
  // Only a real improvement replaces the cut, so rounding cannot make the cost creep up.
  if (best < current - 1e-12 * std::abs(current)) {
    for (int k = 0; k < n; ++k) cut[static_cast<std::size_t>(k)] = lo + path[static_cast<std::size_t>(k)];
  }
}

double seam_cost(const SeamInput& in, const Seams& s, const PixelError& err) {
  const int W = in.cols * in.pitch, H = in.rows * in.pitch;
  const cv::Mat labels = seam_labels(s, in.cols, in.rows, W, H);
  double total = 0;
  for (int y = 0; y < H; ++y) {
    const int* l = labels.ptr<int>(y);
    for (int x = 0; x < W; ++x) total += err(l[x], x, y);
  }
  return total;
}

std::vector<std::vector<int>> straight_cuts(int n, int pitch, int length) {
  std::vector<std::vector<int>> cuts;
  for (int i = 0; i <= n; ++i) cuts.emplace_back(static_cast<std::size_t>(length), i * pitch);
  return cuts;
}

}  // namespace

int side_index(const std::vector<std::vector<int>>& cuts, int pitch, int half, int n, int x, int y) {
  const int i = (x + half) / pitch;  // the cut whose band [i*pitch - half, i*pitch + half) holds x, if any
  if (i >= 1 && i <= n - 1 && x >= i * pitch - half && x < i * pitch + half) {
    return x >= cuts[static_cast<std::size_t>(i)][static_cast<std::size_t>(y)] ? i : i - 1;
  }
  return std::min(x / pitch, n - 1);
}

cv::Rect cell_window(const SeamInput& in, int c, int r) {
  const cv::Rect result(0, 0, in.cols * in.pitch, in.rows * in.pitch);
  return cv::Rect(c * in.pitch - in.half, r * in.pitch - in.half, in.pitch + 2 * in.half,
                  in.pitch + 2 * in.half) &
         result;
}

Seams refine_seams(const SeamInput& in, int iterations) {
  validate(in);
  check(iterations >= 0, "iterations must be >= 0");
  const int cols = in.cols, rows = in.rows, pitch = in.pitch, half = in.half;
  const int W = cols * pitch, H = rows * pitch;
  const PixelError err(in);

  Seams s;
  s.vertical = straight_cuts(cols, pitch, H);
  s.horizontal = straight_cuts(rows, pitch, W);
  s.straight_cost = seam_cost(in, s, err);

  // A vertical cut holds its column over every horizontal band and the row either side; see
  // Seams. Horizontal cuts move freely.
  std::vector<char> v_may_move(static_cast<std::size_t>(H), 1), h_may_move(static_cast<std::size_t>(W), 1);
  for (int j = 1; j < rows; ++j) {
    for (int y = j * pitch - half; y <= j * pitch + half; ++y) v_may_move[static_cast<std::size_t>(y)] = 0;
  }

  for (int it = 0; it < iterations; ++it) {
    for (int i = 1; i < cols; ++i) {
      refine_cut(s.vertical[static_cast<std::size_t>(i)], i, pitch, half, v_may_move,
                 [&](int c, int x, int y) {
                   const int r = side_index(s.horizontal, pitch, half, rows, y, x);
                   return err(r * cols + c, x, y);
                 });
    }
    for (int j = 1; j < rows; ++j) {
      // Along a horizontal cut the roles of x and y swap: step k is column x, position is y.
      refine_cut(s.horizontal[static_cast<std::size_t>(j)], j, pitch, half, h_may_move,
                 [&](int r, int y, int x) {
                   const int c = side_index(s.vertical, pitch, half, cols, x, y);
                   return err(r * cols + c, x, y);
                 });
    }
  }
  s.refined_cost = seam_cost(in, s, err);
  return s;
}

cv::Mat seam_labels(const Seams& seams, int cols, int rows, int W, int H) {
  if (seams.vertical.size() != static_cast<std::size_t>(cols + 1) ||
      seams.horizontal.size() != static_cast<std::size_t>(rows + 1)) {
    throw std::invalid_argument("seam_labels: wrong number of cuts");
  }
  for (const auto& v : seams.vertical) {
    if (v.size() != static_cast<std::size_t>(H)) throw std::invalid_argument("seam_labels: a vertical cut is not H long");
  }
  for (const auto& h : seams.horizontal) {
    if (h.size() != static_cast<std::size_t>(W)) throw std::invalid_argument("seam_labels: a horizontal cut is not W long");
  }
  cv::Mat col(H, W, CV_32S), row(H, W, CV_32S);
  for (int y = 0; y < H; ++y) {
    int* l = col.ptr<int>(y);
    for (int x = 0; x < W; ++x) {
      int c = 0;
      for (int i = 1; i < cols; ++i) c += seams.vertical[static_cast<std::size_t>(i)][static_cast<std::size_t>(y)] <= x;
      l[x] = c;
    }
  }
  for (int x = 0; x < W; ++x) {
    for (int y = 0; y < H; ++y) {
      int r = 0;
      for (int j = 1; j < rows; ++j) r += seams.horizontal[static_cast<std::size_t>(j)][static_cast<std::size_t>(x)] <= y;
      row.at<int>(y, x) = r;
    }
  }
  return row * cols + col;
}

namespace {

// The cut smoothed as a whole line (as WoodPixel fits one least-squares curve per grid line,
// with a slope penalty): s minimises
//   sum_k w_k (s_k - cut_k)^2 + curvature * sum (s_{k-1} - 2 s_k + s_{k+1})^2
//                             + slope * sum (s_{k+1} - s_k)^2,
// w = 1, and 1e6 on fixed steps (which so keep their value). A pentadiagonal SPD system,
// solved by banded Cholesky (LDL^T) in O(n).
std::vector<double> smooth_line(const std::vector<int>& cut, const std::vector<char>& fixed,
                                double curvature, double slope) {
  const int n = static_cast<int>(cut.size());
  // A as three diagonals: d (main), e (first off), f (second off).
  std::vector<double> d(n), e(n, 0.0), f(n, 0.0), b(n);
  for (int k = 0; k < n; ++k) {
    const double w = fixed[static_cast<std::size_t>(k)] ? 1e6 : 1.0;
    d[k] = w;
    b[k] = w * cut[static_cast<std::size_t>(k)];
  }
  for (int k = 0; k + 1 < n; ++k) {  // slope terms (s_{k+1} - s_k)^2
    d[k] += slope, d[k + 1] += slope, e[k] -= slope;
  }
  for (int k = 1; k + 1 < n; ++k) {  // curvature terms, coefficients (1, -2, 1) at k-1, k, k+1
    const int i[3] = {k - 1, k, k + 1};
    const double c[3] = {1, -2, 1};
    for (int a = 0; a < 3; ++a) {
      d[i[a]] += curvature * c[a] * c[a];
      for (int q = a + 1; q < 3; ++q) {
        (q - a == 1 ? e : f)[i[a]] += curvature * c[a] * c[q];
      }
    }
  }
  // LDL^T with L unit lower banded (l1 below the diagonal, l2 two below).
  std::vector<double> D(n), l1(n, 0.0), l2(n, 0.0);
  for (int k = 0; k < n; ++k) {
    double dk = d[k];
    if (k >= 1) dk -= l1[k - 1] * l1[k - 1] * D[k - 1];
    if (k >= 2) dk -= l2[k - 2] * l2[k - 2] * D[k - 2];
    D[k] = dk;
    if (k + 1 < n) {
      double v = e[k];
      if (k >= 1) v -= l2[k - 1] * l1[k - 1] * D[k - 1];
      l1[k] = v / dk;
    }
    if (k + 2 < n) l2[k] = f[k] / dk;
  }
  std::vector<double> y(b);
  for (int k = 0; k < n; ++k) {
    if (k >= 1) y[k] -= l1[k - 1] * y[k - 1];
    if (k >= 2) y[k] -= l2[k - 2] * y[k - 2];
  }
  for (int k = 0; k < n; ++k) y[k] /= D[k];
  for (int k = n - 1; k >= 0; --k) {
    if (k + 1 < n) y[k] -= l1[k] * y[k + 1];
    if (k + 2 < n) y[k] -= l2[k] * y[k + 2];
  }
  return y;
}

// One interior cut as a polyline: the boundary value at step k sits at k + 0.5 along the cut,
// the ends at 0 and `length`. The whole line smoothed (smooth_line); `fixed[k]` steps keep
// their raw value (and no knot inside a fixed run). `point(along, across)` builds the point.
template <typename MakePoint>
std::vector<cv::Point2d> cut_polyline(const std::vector<int>& cut, const std::vector<char>& fixed,
                                      double knot_px, double curvature, double slope, MakePoint point) {
  const int n = static_cast<int>(cut.size());
  std::vector<double> s = smooth_line(cut, fixed, curvature, slope);
  for (int k = 0; k < n; ++k) {
    if (fixed[static_cast<std::size_t>(k)]) s[static_cast<std::size_t>(k)] = cut[static_cast<std::size_t>(k)];
  }
  // Each Bezier segment lies in the hull of its control points, which Catmull-Rom puts up to
  // a sixth of the neighbours' spread beyond the knots: knots kept an eighth of the cut's
  // range inside it keep the whole curve inside the range (so inside the band and the window).
  const auto [lo, hi] = std::minmax_element(cut.begin(), cut.end());
  const double margin = (*hi - *lo) / 8.0;
  for (double& v : s) v = std::clamp(v, *lo + margin, *hi - margin);
  // Forced knots: the ends of every fixed run, so the line is straight across it.
  std::vector<char> knot(static_cast<std::size_t>(n), 0), inside(static_cast<std::size_t>(n), 0);
  std::vector<double> forced = {0.0, static_cast<double>(n)};
  for (int k = 0; k < n; ++k) {
    if (!fixed[static_cast<std::size_t>(k)]) continue;
    const bool first = k == 0 || !fixed[static_cast<std::size_t>(k - 1)];
    const bool last = k == n - 1 || !fixed[static_cast<std::size_t>(k + 1)];
    if (first || last) {
      knot[static_cast<std::size_t>(k)] = 1;
      forced.push_back(k + 0.5);
    }
    if (!first && !last) inside[static_cast<std::size_t>(k)] = 1;
  }
  // Regular knots about every knot_px, none crowding a forced one.
  const double step = std::max(1.0, knot_px);
  for (double at = step; at < n; at += step) {
    const int k = std::clamp(static_cast<int>(std::lround(at - 0.5)), 0, n - 1);
    if (inside[static_cast<std::size_t>(k)]) continue;
    const bool crowded = std::any_of(forced.begin(), forced.end(),
                                     [&](double f) { return std::abs(f - (k + 0.5)) < step / 2; });
    if (!crowded) knot[static_cast<std::size_t>(k)] = 1;
  }
  std::vector<cv::Point2d> line = {point(0.0, s.front())};
  for (int k = 0; k < n; ++k) {
    if (knot[static_cast<std::size_t>(k)]) line.push_back(point(k + 0.5, s[static_cast<std::size_t>(k)]));
  }
  line.push_back(point(static_cast<double>(n), s.back()));
  return line;
}

}  // namespace

GridLines seam_lines(const Seams& seams, int cols, int rows, int pitch, double knot_px) {
  const int W = cols * pitch, H = rows * pitch;
  if (cols < 1 || rows < 1 || pitch < 3 || !(knot_px > 0) ||
      seams.vertical.size() != static_cast<std::size_t>(cols + 1) ||
      seams.horizontal.size() != static_cast<std::size_t>(rows + 1)) {
    throw std::invalid_argument("seam_lines: seams do not match a " + std::to_string(cols) + " x " +
                                std::to_string(rows) + " grid");
  }
  // Each horizontal cut j spans rows [lo_j, hi_j]; a vertical line straight over the rows
  // lo_j - 1 .. hi_j (pixel centres lo_j - 0.5 .. hi_j + 0.5) meets it exactly once, where it
  // passes that column. refine_seams holds vertical cuts still there (see Seams).
  std::vector<char> v_fixed(static_cast<std::size_t>(H), 0), h_fixed(static_cast<std::size_t>(W), 0);
  for (int j = 1; j < rows; ++j) {
    const auto& h = seams.horizontal[static_cast<std::size_t>(j)];
    if (h.size() != static_cast<std::size_t>(W)) throw std::invalid_argument("seam_lines: a horizontal cut is not W long");
    const auto [lo, hi] = std::minmax_element(h.begin(), h.end());
    if (*lo < 1 || *hi > H - 1) throw std::invalid_argument("seam_lines: horizontal cut " + std::to_string(j) + " leaves the result");
    for (int y = *lo - 1; y <= *hi; ++y) v_fixed[static_cast<std::size_t>(y)] = 1;
  }
  for (int i = 1; i < cols; ++i) {
    const auto& v = seams.vertical[static_cast<std::size_t>(i)];
    if (v.size() != static_cast<std::size_t>(H)) throw std::invalid_argument("seam_lines: a vertical cut is not H long");
    for (int y = 1; y < H; ++y) {
      if (v_fixed[static_cast<std::size_t>(y)] && v_fixed[static_cast<std::size_t>(y - 1)] &&
          v[static_cast<std::size_t>(y)] != v[static_cast<std::size_t>(y - 1)]) {
        throw std::invalid_argument("seam_lines: vertical cut " + std::to_string(i) + " bends in row " +
                                    std::to_string(y) + " where a horizontal cut passes");
      }
    }
  }
  // Deviations shorter than about a pitch are smoothed away (the smoother's half-power
  // wavelength is 2 pi curvature^(1/4)); the slope term keeps the rest gentle.
  const double curvature = std::pow(pitch / (2 * CV_PI), 4), slope = std::pow(pitch / (2 * CV_PI), 2);
  GridLines g;
  g.cols = cols;
  g.rows = rows;
  g.vertical.push_back({{0.0, 0.0}, {0.0, static_cast<double>(H)}});
  for (int i = 1; i < cols; ++i) {
    const auto& cut = seams.vertical[static_cast<std::size_t>(i)];
    g.vertical.push_back(cut_polyline(cut, v_fixed, knot_px, curvature, slope, [](double along, double across) {
      return cv::Point2d(across, along);
    }));
  }
  g.vertical.push_back({{static_cast<double>(W), 0.0}, {static_cast<double>(W), static_cast<double>(H)}});
  g.horizontal.push_back({{0.0, 0.0}, {static_cast<double>(W), 0.0}});
  for (int j = 1; j < rows; ++j) {
    const auto& cut = seams.horizontal[static_cast<std::size_t>(j)];
    g.horizontal.push_back(cut_polyline(cut, h_fixed, knot_px, curvature, slope, [](double along, double across) {
      return cv::Point2d(along, across);
    }));
  }
  g.horizontal.push_back({{0.0, static_cast<double>(H)}, {static_cast<double>(W), static_cast<double>(H)}});
  return g;
}

}  // namespace atelier::parquetry
