// A curvilinear grid of patches (paper 3.4): the lines of a regular, morphed or cut-refined
// grid, and the closed outline of every cell with cubic Bezier edges that neighbouring cells
// share exactly.
//
// Units: whatever the caller uses (pixels or mm), y down. Pure, thread-safe.
#pragma once

#include <vector>

#include "algorithms/parquetry/outline.h"

namespace atelier::parquetry {

// cols + 1 "vertical" lines (each a polyline from the top border to the bottom border) and
// rows + 1 "horizontal" lines (left border to right border). vertical[0] / vertical[cols]
// are the left / right borders, horizontal[0] / horizontal[rows] the top / bottom ones.
// Vertical line i and horizontal line j cross exactly once.
struct GridLines {
  int cols = 0, rows = 0;
  std::vector<std::vector<cv::Point2d>> vertical;
  std::vector<std::vector<cv::Point2d>> horizontal;
};

// The straight lines of a regular cols x rows grid of `pitch` squares from (0, 0).
GridLines regular_lines(int cols, int rows, double pitch);

// Outline of every cell, row-major (cell (c, r) at r * cols + c), clockwise on screen from
// the crossing of vertical c and horizontal r: along horizontal r to vertical c + 1, down
// vertical c + 1 to horizontal r + 1, back along horizontal r + 1, up vertical c. Each line
// is fitted once as a G1 Catmull-Rom spline through its points with the crossings inserted
// as knots, so two cells share the very same curve (reversed) and the cells tile the result
// without gaps or overlaps. Straight lines stay straight. A line point closer to a crossing
// than a quarter of its other segment is dropped (a near-zero segment makes Catmull-Rom
// loop), so the curve may pass up to that far from the dropped point. Throws std::invalid_argument when
// the lines do not form a grid (wrong counts, a pair that does not cross).
std::vector<Outline> cell_outlines(const GridLines& lines);

}  // namespace atelier::parquetry
