// A-posteriori cut refinement (paper 3.4, eq. 8-9): neighbouring patches are matched on
// windows that overlap by `half` px on every side, and the cut between them is moved inside
// the overlap to where the wood matches the target best, by dynamic programming per cut.
//
// Units: working pixels of the result (1 px = 1 / px_per_mm mm), y down; pixel x spans
// [x, x + 1). Pure, no shared state: thread-safe.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "algorithms/parquetry/curved_grid.h"

namespace atelier::parquetry {

// Grid of refine = dp in working pixels. Cell (c, r) owns the core square [c*pitch, (c+1)*pitch) x
// [r*pitch, (r+1)*pitch); its matched wood window reaches `half` px beyond the core on every side,
// clipped to the result (W = cols*pitch, H = rows*pitch). 1 <= half < pitch / 2.
struct SeamInput {
  int cols = 0, rows = 0, pitch = 0, half = 0;
  cv::Mat target_f1, target_f2;              // CV_32F, H x W: target features (eq. 1-2)
  std::vector<cv::Mat> wood_f1, wood_f2;     // per cell, row-major: the matched wood's features over
                                             // cell_window(c, r) (CV_32F of that size)
  // Per cell (or empty = all): CV_8UC1 over its window, 255 where its wood may be used; a
  // cut never gives a cell a pixel outside. Each cell's core must be available.
  std::vector<cv::Mat> available;
};

// Index (0 .. n-1) of the cell along one axis at coordinate `x` in scan line `y` under `cuts`
// (the n + 1 cuts across that axis, each within its band [i*pitch - half, i*pitch + half]):
// a pixel outside every band is in the cell its grid square says, whatever the cuts do.
int side_index(const std::vector<std::vector<int>>& cuts, int pitch, int half, int n, int x, int y);

// Window of cell (c, r) in result px, clipped to the result.
cv::Rect cell_window(const SeamInput& in, int c, int r);

struct Seams {
  // vertical[i][y], y in [0, H): the first pixel column of the cell right of line i in pixel row y.
  // vertical[0] is all 0, vertical[cols] all W; interior lines stay within [i*pitch - half, i*pitch + half]
  // and move at most 1 px from one row to the next (connected cuts, paper: 6-connectivity).
  // Where a horizontal cut j can pass (rows j*pitch - half - 1 .. j*pitch + half), vertical cuts
  // hold one column: then every cell's region stays 4-connected however the horizontal cut
  // bends there (no two cuts running along the same diagonal pinching a corner off).
  std::vector<std::vector<int>> vertical;
  std::vector<std::vector<int>> horizontal;  // horizontal[j][x], the same by columns
  double straight_cost = 0;  // eq. 8 over the result with every cut on its grid line
  double refined_cost = 0;   // eq. 8 with the refined cuts
};

// Eq. 9 by dynamic programming per cut, the cell on each side of a pixel decided by the cuts of
// the other direction; where four patches meet, alternate: all vertical cuts with the horizontal
// ones fixed, then all horizontal ones, `iterations` times (the paper: 2). Starts from straight
// cuts. Each pass minimises eq. 8 exactly over one cut with the others fixed, so the cost never
// rises: refined_cost <= straight_cost. Throws std::invalid_argument on inconsistent input
// (sizes, half out of range, iterations < 0).
Seams refine_seams(const SeamInput& in, int iterations = 2);

// Cell index (r * cols + c) of every result pixel under `seams` (CV_32S, H x W): c = number of
// interior vertical cuts i with vertical[i][y] <= x, r likewise.
cv::Mat seam_labels(const Seams& seams, int cols, int rows, int W, int H);

// The cuts as grid lines in pixel coordinates (continuous: pixel x spans [x, x+1)) for
// cell_outlines: vertical line i through (vertical[i][y], y + 0.5) (the boundary between pixel
// columns), from y = 0 to y = H, lightly smoothed (so the laser cuts curves, not 1-px stairs)
// and thinned to knots about every `knot_px` px; borders straight. Smoothing is a moving
// average (a convex mix, so each line stays inside its band); a vertical line runs straight
// over the rows each horizontal cut spans, so each pair of lines crosses exactly once. Throws
// std::invalid_argument for seams that do not fit the grid or bend there (refine_seams' never do).
GridLines seam_lines(const Seams& seams, int cols, int rows, int pitch, double knot_px);

}  // namespace atelier::parquetry
