// Plane geometry for laser toolpaths: points, polylines, Bezier flattening, containment.
//
// Units are millimetres throughout. Pure functions, no state: thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace atelier::laser {

struct Point {
  double x = 0, y = 0;
};

// A polyline. `closed`: the last point joins the first (the closing segment is implied,
// the first point is not repeated at the end).
struct Path {
  std::vector<Point> points;
  bool closed = false;
};

// Axis-aligned box; a default-constructed Bounds is empty (min > max).
struct Bounds {
  double min_x = 1e300, min_y = 1e300, max_x = -1e300, max_y = -1e300;
  bool empty() const { return min_x > max_x || min_y > max_y; }
  void add(Point p);
  void add(const Bounds& b);
  bool contains(const Bounds& inner) const;
};

// Appends the flattened cubic p0..p3 (p0 excluded, p3 included) so that no chord deviates
// from the curve by more than `tolerance_mm` (adaptive subdivision; tolerance is clamped to
// at least 1e-4 mm). Returns false, having stopped early, when `out` would grow beyond
// `max_points` points (a budget for the whole drawing: `out` never holds more); true
// otherwise. Non-finite control points append nothing and return false.
bool flatten_cubic(Point p0, Point p1, Point p2, Point p3, double tolerance_mm,
                   std::vector<Point>& out, size_t max_points = SIZE_MAX);

double distance(Point a, Point b);
// Distance from `p` to the segment a..b.
double distance_to_segment(Point p, Point a, Point b);
// Length of the polyline, including the closing segment of a closed path.
double path_length(const Path& path);
Bounds bounds_of(const Path& path);
// Signed area (shoelace); positive when counter-clockwise in a y-up frame.
double signed_area(const std::vector<Point>& ring);
// Even-odd point-in-polygon test of `p` against the ring `ring` (implicitly closed).
bool point_in_polygon(Point p, const std::vector<Point>& ring);

}  // namespace atelier::laser
