#include "algorithms/laser/geometry.h"

#include <algorithm>
#include <cmath>

namespace atelier::laser {
namespace {

Point mid(Point a, Point b) { return {(a.x + b.x) / 2, (a.y + b.y) / 2}; }

// The curve lies in the convex hull of its control points, so when both inner control
// points are within `tol` of the chord, so is every point of the curve.
// Returns false when the budget `max_points` is used up.
bool subdivide(Point p0, Point p1, Point p2, Point p3, double tol, int depth,
               std::vector<Point>& out, size_t max_points) {
  if (depth >= 24 ||
      (distance_to_segment(p1, p0, p3) <= tol && distance_to_segment(p2, p0, p3) <= tol)) {
    if (out.size() >= max_points) return false;
    out.push_back(p3);
    return true;
  }
  // de Casteljau split at t = 0.5.
  Point p01 = mid(p0, p1), p12 = mid(p1, p2), p23 = mid(p2, p3);
  Point p012 = mid(p01, p12), p123 = mid(p12, p23);
  Point m = mid(p012, p123);
  return subdivide(p0, p01, p012, m, tol, depth + 1, out, max_points) &&
         subdivide(m, p123, p23, p3, tol, depth + 1, out, max_points);
}

bool finite(Point p) { return std::isfinite(p.x) && std::isfinite(p.y); }

}  // namespace

void Bounds::add(Point p) {
  min_x = std::min(min_x, p.x);
  min_y = std::min(min_y, p.y);
  max_x = std::max(max_x, p.x);
  max_y = std::max(max_y, p.y);
}

void Bounds::add(const Bounds& b) {
  if (b.empty()) return;
  add(Point{b.min_x, b.min_y});
  add(Point{b.max_x, b.max_y});
}

bool Bounds::contains(const Bounds& inner) const {
  return !empty() && !inner.empty() && inner.min_x >= min_x && inner.max_x <= max_x &&
         inner.min_y >= min_y && inner.max_y <= max_y;
}

bool flatten_cubic(Point p0, Point p1, Point p2, Point p3, double tolerance_mm,
                   std::vector<Point>& out, size_t max_points) {
  // A NaN fails every tolerance test and would subdivide to the full depth (2^24 points).
  if (!finite(p0) || !finite(p1) || !finite(p2) || !finite(p3)) return false;
  return subdivide(p0, p1, p2, p3, std::max(tolerance_mm, 1e-4), 0, out, max_points);
}

double distance(Point a, Point b) { return std::hypot(a.x - b.x, a.y - b.y); }

double distance_to_segment(Point p, Point a, Point b) {
  double dx = b.x - a.x, dy = b.y - a.y;
  double len2 = dx * dx + dy * dy;
  if (len2 <= 0) return distance(p, a);
  double t = std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / len2, 0.0, 1.0);
  return distance(p, Point{a.x + t * dx, a.y + t * dy});
}

double path_length(const Path& path) {
  const auto& pts = path.points;
  double len = 0;
  for (size_t i = 1; i < pts.size(); ++i) len += distance(pts[i - 1], pts[i]);
  if (path.closed && pts.size() > 1) len += distance(pts.back(), pts.front());
  return len;
}

Bounds bounds_of(const Path& path) {
  Bounds b;
  for (Point p : path.points) b.add(p);
  return b;
}

double signed_area(const std::vector<Point>& ring) {
  double a = 0;
  for (size_t i = 0, n = ring.size(); i < n; ++i) {
    Point p = ring[i], q = ring[(i + 1) % n];
    a += p.x * q.y - q.x * p.y;
  }
  return a / 2;
}

bool point_in_polygon(Point p, const std::vector<Point>& ring) {
  bool inside = false;
  for (size_t i = 0, n = ring.size(), j = n - 1; i < n; j = i++) {
    Point a = ring[i], b = ring[j];
    if ((a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x) {
      inside = !inside;
    }
  }
  return inside;
}

}  // namespace atelier::laser
