#include "algorithms/parquetry/outline.h"

#include <algorithm>
#include <cmath>

namespace atelier::parquetry {

namespace {

void subdivide(const Cubic& c, double tol, int depth, std::vector<cv::Point2d>& out) {
  // Flat enough when both control points lie within tol of the chord.
  const cv::Point2d d = c.p3 - c.p0;
  const double len = std::hypot(d.x, d.y);
  auto dist = [&](cv::Point2d p) {
    if (len < 1e-12) return cv::norm(p - c.p0);
    return std::abs((p - c.p0).cross(d)) / len;
  };
  if (depth >= 16 || std::max(dist(c.c1), dist(c.c2)) <= tol) {
    out.push_back(c.p3);
    return;
  }
  const cv::Point2d a = (c.p0 + c.c1) * 0.5, b = (c.c1 + c.c2) * 0.5, e = (c.c2 + c.p3) * 0.5;
  const cv::Point2d ab = (a + b) * 0.5, be = (b + e) * 0.5, mid = (ab + be) * 0.5;
  subdivide({c.p0, a, ab, mid}, tol, depth + 1, out);
  subdivide({mid, be, e, c.p3}, tol, depth + 1, out);
}

}  // namespace

Cubic straight(cv::Point2d a, cv::Point2d b) {
  return {a, a + (b - a) * (1.0 / 3.0), a + (b - a) * (2.0 / 3.0), b};
}

Outline polygon_outline(const std::vector<cv::Point2d>& corners) {
  Outline out;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    out.push_back(straight(corners[i], corners[(i + 1) % corners.size()]));
  }
  return out;
}

std::vector<Cubic> catmull_rom(const std::vector<cv::Point2d>& p) {
  std::vector<Cubic> out;
  const std::size_t n = p.size();
  if (n < 2) return out;
  if (n == 2) return {straight(p[0], p[1])};
  auto at = [&](long i) -> cv::Point2d {
    if (i < 0) return p[0] * 2.0 - p[1];
    if (i >= static_cast<long>(n)) return p[n - 1] * 2.0 - p[n - 2];
    return p[static_cast<std::size_t>(i)];
  };
  for (long k = 0; k + 1 < static_cast<long>(n); ++k) {
    const cv::Point2d t0 = (at(k + 1) - at(k - 1)) * 0.5, t1 = (at(k + 2) - at(k)) * 0.5;
    out.push_back({at(k), at(k) + t0 * (1.0 / 3.0), at(k + 1) - t1 * (1.0 / 3.0), at(k + 1)});
  }
  return out;
}

std::vector<Cubic> reversed(const std::vector<Cubic>& curve) {
  std::vector<Cubic> out;
  for (auto it = curve.rbegin(); it != curve.rend(); ++it) out.push_back({it->p3, it->c2, it->c1, it->p0});
  return out;
}

std::vector<cv::Point2d> flatten(const Outline& outline, double tolerance) {
  std::vector<cv::Point2d> out;
  if (outline.empty()) return out;
  out.push_back(outline.front().p0);
  for (const Cubic& c : outline) subdivide(c, std::max(tolerance, 1e-6), 0, out);
  if (out.size() > 1 && cv::norm(out.back() - out.front()) < 1e-9) out.pop_back();
  return out;
}

cv::Point2d transformed(cv::Point2d p, const cv::Matx23d& m) {
  return {m(0, 0) * p.x + m(0, 1) * p.y + m(0, 2), m(1, 0) * p.x + m(1, 1) * p.y + m(1, 2)};
}

Outline transformed(const Outline& outline, const cv::Matx23d& m) {
  Outline out;
  for (const Cubic& c : outline) {
    out.push_back({transformed(c.p0, m), transformed(c.c1, m), transformed(c.c2, m),
                   transformed(c.p3, m)});
  }
  return out;
}

double polygon_area(const std::vector<cv::Point2d>& p) {
  double a = 0;
  for (std::size_t i = 0; i < p.size(); ++i) a += p[i].cross(p[(i + 1) % p.size()]);
  return a / 2;
}

}  // namespace atelier::parquetry
