// The Fair-Isle float constraint (paper section 3): no run of more than f equal stitches.
//
// A constraint is a window of f+1 consecutive stitches in a row; it is violated when all of
// them have one colour. A run of L equal stitches therefore violates max(0, L - f) windows.
// Relaxed stitches (mask != 0) take their windows out of the problem; with anchoring off,
// runs touching the first or last stitch of the row are free (the idle yarn is carried at
// the side). Pure, thread-safe.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace atelier::knit {

struct FloatRules {
  int max_float = 4;       // f, the longest allowed run of one colour (>= 2)
  bool anchoring = true;   // false: runs that touch a row edge are not constrained
  cv::Mat relax;           // empty, or CV_8UC1 of the grid's size; nonzero = relaxed
};

// A maximal run of equal, non-relaxed stitches in one row that violates the constraint.
struct Run {
  int row;
  int start;   // first column
  int length;  // number of stitches, > max_float
};

// Number of violated constraints in the whole grid / in one row.
long count_violations(const cv::Mat& grid, const FloatRules& rules);
long count_row_violations(const cv::Mat& grid, int row, const FloatRules& rules);

// Every violating run, row by row, left to right.
std::vector<Run> violating_runs(const cv::Mat& grid, const FloatRules& rules);

// Number of stitches that take part in no violated constraint.
long consistent_stitches(const cv::Mat& grid, const FloatRules& rules);

// Longest run of one colour in any row, counting only constrained stitches (relaxed stitches
// and, with anchoring off, edge runs excluded): the float a knitter actually gets.
int longest_float(const cv::Mat& grid, const FloatRules& rules);

}  // namespace atelier::knit
