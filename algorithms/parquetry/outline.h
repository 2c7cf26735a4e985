// Piece outlines: closed paths of cubic Bezier segments (the paper's "cuts fitted with cubic
// Bezier curve segments"), and the helpers to build, move and flatten them.
//
// Units are whatever the caller uses (result mm, sheet mm or pixels); nothing here scales.
// Pure functions on values: thread-safe.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace atelier::parquetry {

struct Cubic {
  cv::Point2d p0, c1, c2, p3;
};

// A closed outline: segment k ends where segment k+1 starts, the last ends at the first's p0.
using Outline = std::vector<Cubic>;

// A straight segment as a cubic (control points at the thirds).
Cubic straight(cv::Point2d a, cv::Point2d b);

// The closed polygon through `corners` with straight edges.
Outline polygon_outline(const std::vector<cv::Point2d>& corners);

// A G1 (C1) curve through `points` in order (uniform Catmull-Rom, end tangents by
// reflection): points.size() - 1 cubic segments, segment k from points[k] to points[k+1].
// Two points give one straight segment.
std::vector<Cubic> catmull_rom(const std::vector<cv::Point2d>& points);

// The same segments backwards.
std::vector<Cubic> reversed(const std::vector<Cubic>& curve);

// Closed polygon approximating `outline` within `tolerance` (adaptive subdivision); the first
// point is not repeated at the end.
std::vector<cv::Point2d> flatten(const Outline& outline, double tolerance);

// `outline` mapped by the affine transform `m` (p' = m * (x, y, 1)).
Outline transformed(const Outline& outline, const cv::Matx23d& m);
cv::Point2d transformed(cv::Point2d p, const cv::Matx23d& m);

// Signed area of a closed polygon (shoelace; positive when clockwise on screen, y down).
double polygon_area(const std::vector<cv::Point2d>& polygon);

}  // namespace atelier::parquetry
