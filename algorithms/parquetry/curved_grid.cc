#include "algorithms/parquetry/curved_grid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace atelier::parquetry {

namespace {

using Line = std::vector<cv::Point2d>;

// Points closer than this to a crossing are the crossing (units of the caller).
constexpr double kSamePoint = 1e-6;

// Where along a polyline a crossing lies: segment index + fraction, and the point.
struct Crossing {
  double at = 0;  // segment index + t in [0, 1]
  cv::Point2d p;
};

std::string line_name(bool vertical, int i) {
  return std::string(vertical ? "vertical" : "horizontal") + " line " + std::to_string(i);
}

// The single crossing of polylines a and b, as a position along each. Touching ends count
// (the borders meet the other lines at their end points).
void cross(const Line& a, const Line& b, int ia, int ib, Crossing& on_a, Crossing& on_b) {
  constexpr double eps = 1e-9;
  bool found = false;
  for (std::size_t s = 0; s + 1 < a.size(); ++s) {
    const cv::Point2d a0 = a[s], d = a[s + 1] - a[s];
    const double ax0 = std::min(a0.x, a[s + 1].x), ax1 = std::max(a0.x, a[s + 1].x);
    const double ay0 = std::min(a0.y, a[s + 1].y), ay1 = std::max(a0.y, a[s + 1].y);
    for (std::size_t u = 0; u + 1 < b.size(); ++u) {
      const cv::Point2d b0 = b[u], e = b[u + 1] - b[u];
      // Cheap box rejection first: most segment pairs are far apart.
      if (std::max(b0.x, b[u + 1].x) < ax0 - eps || std::min(b0.x, b[u + 1].x) > ax1 + eps ||
          std::max(b0.y, b[u + 1].y) < ay0 - eps || std::min(b0.y, b[u + 1].y) > ay1 + eps) {
        continue;
      }
      const double den = d.cross(e);
      if (std::abs(den) <= 1e-12 * cv::norm(d) * cv::norm(e)) continue;  // parallel
      const cv::Point2d w = b0 - a0;
      const double t = w.cross(e) / den, v = w.cross(d) / den;
      if (t < -eps || t > 1 + eps || v < -eps || v > 1 + eps) continue;
      const double tc = std::clamp(t, 0.0, 1.0), vc = std::clamp(v, 0.0, 1.0);
      const cv::Point2d p = a0 + d * tc;
      if (found) {
        // The same crossing seen again at a shared vertex is fine; a second one is not.
        if (cv::norm(p - on_a.p) <= kSamePoint) continue;
        throw std::invalid_argument(line_name(true, ia) + " and " + line_name(false, ib) +
                                    " cross more than once");
      }
      found = true;
      on_a = {static_cast<double>(s) + tc, p};
      on_b = {static_cast<double>(u) + vc, p};
    }
  }
  if (!found) {
    throw std::invalid_argument(line_name(true, ia) + " and " + line_name(false, ib) +
                                " do not cross");
  }
}

bool collinear(const Line& knots) {
  const cv::Point2d a = knots.front(), d = knots.back() - a;
  const double len = cv::norm(d);
  if (len < 1e-12) return false;
  for (const cv::Point2d& p : knots) {
    if (std::abs((p - a).cross(d)) / len > 1e-9 * std::max(1.0, len)) return false;
  }
  return true;
}

// A line fitted once through its points with its crossings as knots; edge k runs over
// curve[knot[k] .. knot[k + 1]).
struct FittedLine {
  std::vector<Cubic> curve;
  std::vector<std::size_t> knot;  // knot index of each crossing, in crossing order
};

FittedLine fit(const Line& line, const std::vector<Crossing>& crossings, bool vertical, int index) {
  for (std::size_t k = 1; k < crossings.size(); ++k) {
    if (!(crossings[k].at > crossings[k - 1].at) ||
        cv::norm(crossings[k].p - crossings[k - 1].p) <= kSamePoint) {
      throw std::invalid_argument(line_name(vertical, index) + " meets the lines " +
                                  std::to_string(k - 1) + " and " + std::to_string(k) +
                                  " of the other direction out of order or at one point");
    }
  }
  auto near_crossing = [&](cv::Point2d p) {
    return std::any_of(crossings.begin(), crossings.end(),
                       [&](const Crossing& c) { return cv::norm(p - c.p) <= kSamePoint; });
  };
  Line knots;
  FittedLine out;
  std::size_t next = 0;
  for (std::size_t s = 0; s < line.size(); ++s) {
    // Crossings up to point s (at <= s) come before it; at == s replaces the point.
    while (next < crossings.size() && crossings[next].at <= static_cast<double>(s)) {
      out.knot.push_back(knots.size());
      knots.push_back(crossings[next++].p);
    }
    if (!near_crossing(line[s])) knots.push_back(line[s]);
  }
  while (next < crossings.size()) {
    out.knot.push_back(knots.size());
    knots.push_back(crossings[next++].p);
  }
  // A line point much closer to a crossing than to its other neighbour would leave a tiny
  // segment, and uniform Catmull-Rom loops on it (the loop then lies in both neighbouring
  // cells). Such a point goes; the curve runs through the crossing instead, at most a quarter
  // of the sampling away from it.
  std::vector<char> is_crossing(knots.size(), 0), drop(knots.size(), 0);
  for (std::size_t q : out.knot) is_crossing[q] = 1;
  for (std::size_t q : out.knot) {
    for (int dir : {-1, 1}) {
      const long n = static_cast<long>(q) + dir, o = n + dir;
      if (n <= 0 || o < 0 || n >= static_cast<long>(knots.size()) - 1 || o >= static_cast<long>(knots.size())) continue;
      if (is_crossing[n]) continue;
      if (cv::norm(knots[n] - knots[q]) < 0.25 * cv::norm(knots[o] - knots[n])) drop[n] = 1;
    }
  }
  Line kept;
  std::vector<std::size_t> moved(knots.size());
  for (std::size_t k = 0; k < knots.size(); ++k) {
    moved[k] = kept.size();
    if (!drop[k]) kept.push_back(knots[k]);
  }
  for (std::size_t& q : out.knot) q = moved[q];
  knots.swap(kept);
  // Catmull-Rom through unevenly spaced collinear points can run back and forth along the
  // line; a straight line stays exactly straight.
  if (collinear(knots)) {
    for (std::size_t k = 0; k + 1 < knots.size(); ++k) out.curve.push_back(straight(knots[k], knots[k + 1]));
  } else {
    out.curve = catmull_rom(knots);
  }
  return out;
}

void append(Outline& out, const std::vector<Cubic>& curve, std::size_t from, std::size_t to) {
  if (from < to) {
    out.insert(out.end(), curve.begin() + static_cast<long>(from), curve.begin() + static_cast<long>(to));
  } else {
    for (std::size_t k = from; k > to; --k) {
      const Cubic& c = curve[k - 1];
      out.push_back({c.p3, c.c2, c.c1, c.p0});
    }
  }
}

}  // namespace

GridLines regular_lines(int cols, int rows, double pitch) {
  if (cols < 1 || rows < 1 || !(pitch > 0)) {
    throw std::invalid_argument("regular_lines: needs cols, rows >= 1 and pitch > 0");
  }
  GridLines g;
  g.cols = cols;
  g.rows = rows;
  const double w = cols * pitch, h = rows * pitch;
  for (int i = 0; i <= cols; ++i) g.vertical.push_back({{i * pitch, 0.0}, {i * pitch, h}});
  for (int j = 0; j <= rows; ++j) g.horizontal.push_back({{0.0, j * pitch}, {w, j * pitch}});
  return g;
}

std::vector<Outline> cell_outlines(const GridLines& lines) {
  const int cols = lines.cols, rows = lines.rows;
  if (cols < 1 || rows < 1 || lines.vertical.size() != static_cast<std::size_t>(cols + 1) ||
      lines.horizontal.size() != static_cast<std::size_t>(rows + 1)) {
    throw std::invalid_argument("cell_outlines: a " + std::to_string(cols) + " x " +
                                std::to_string(rows) + " grid needs " + std::to_string(cols + 1) +
                                " vertical and " + std::to_string(rows + 1) +
                                " horizontal lines, got " + std::to_string(lines.vertical.size()) +
                                " and " + std::to_string(lines.horizontal.size()));
  }
  for (int i = 0; i <= cols; ++i) {
    if (lines.vertical[static_cast<std::size_t>(i)].size() < 2) {
      throw std::invalid_argument(line_name(true, i) + " has fewer than 2 points");
    }
  }
  for (int j = 0; j <= rows; ++j) {
    if (lines.horizontal[static_cast<std::size_t>(j)].size() < 2) {
      throw std::invalid_argument(line_name(false, j) + " has fewer than 2 points");
    }
  }
  // on_v[i][j]: crossing of vertical i with horizontal j, as a position along vertical i.
  std::vector<std::vector<Crossing>> on_v(cols + 1, std::vector<Crossing>(rows + 1));
  std::vector<std::vector<Crossing>> on_h(rows + 1, std::vector<Crossing>(cols + 1));
  for (int i = 0; i <= cols; ++i) {
    for (int j = 0; j <= rows; ++j) {
      cross(lines.vertical[i], lines.horizontal[j], i, j, on_v[i][j], on_h[j][i]);
      on_h[j][i].p = on_v[i][j].p;  // one point, bitwise, in both lines
    }
  }
  std::vector<FittedLine> v, h;
  for (int i = 0; i <= cols; ++i) v.push_back(fit(lines.vertical[i], on_v[i], true, i));
  for (int j = 0; j <= rows; ++j) h.push_back(fit(lines.horizontal[j], on_h[j], false, j));

  std::vector<Outline> cells;
  cells.reserve(static_cast<std::size_t>(cols * rows));
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      Outline o;
      append(o, h[r].curve, h[r].knot[c], h[r].knot[c + 1]);                  // top, rightwards
      append(o, v[c + 1].curve, v[c + 1].knot[r], v[c + 1].knot[r + 1]);      // right, down
      append(o, h[r + 1].curve, h[r + 1].knot[c + 1], h[r + 1].knot[c]);      // bottom, leftwards
      append(o, v[c].curve, v[c].knot[r + 1], v[c].knot[r]);                  // left, up
      cells.push_back(std::move(o));
    }
  }
  return cells;
}

}  // namespace atelier::parquetry
