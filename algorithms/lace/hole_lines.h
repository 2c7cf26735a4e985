// Where the holes of a lace chart sit and whether they form lines (issue 22 lace point 4; the
// "connectedness of the holes" Ekart 2007 section 6 proposes as a further objective).
//
// Column layout: a stitch sits over the stitches of the row below it is worked over, so its
// column is the mean column of those stitches; a yarn-over (worked over none) sits between the
// stitches of the row below on either side of it (half a column before the first / after the
// last at the row's ends). The cast-on stitches are columns 0 .. cast_on-1. Columns are in
// stitches of the cast-on, real-valued (a yarn-over paired with a k2tog sits at x.5).
// Pure functions on value types, thread-safe.
#pragma once

#include <vector>

#include "algorithms/lace/chart.h"

namespace atelier::lace {

// columns[r][j]: the column of stitch j of row r (knitting order, as chart.h). The rows must
// follow on from each other and row 0 be worked over cast_on stitches (any other chart throws
// std::invalid_argument).
std::vector<std::vector<double>> stitch_columns(const Chart& chart, int cast_on);

// Two holes on consecutive rows are in one line when their columns differ by at most this
// (offset -1, 0 or +1 column: verticals and diagonals), measured round the repeat (columns
// modulo cast_on: the chart is tiled side by side).
inline constexpr double kHoleLineReach = 1.0;

struct HoleLines {
  long cells = 0;       // stitches of all rows
  long yarn_overs = 0;  // holes
  long connected = 0;   // holes with a hole in the row above or below within kHoleLineReach
  double yo_share = 0;  // yarn_overs / cells, 0..1
  long in_lines = 0;    // holes in a line spanning at least kHoleLineRows rows
  // connected / yarn_overs, 0..1; 0 without holes. Dense random meshes score high on it too (at
  // 35 % holes almost every hole has one near it), so it is reported, not optimised.
  double connectedness = 0;
  // in_lines / yarn_overs, 0..1; 0 without holes: the holes of the chart that are part of a line
  // (holes joined row to row within kHoleLineReach, the chain reaching over at least
  // kHoleLineRows consecutive rows). Diagonal or vertical lines of eyelets score 1, a random
  // mesh at 20 % holes about 0.3-0.5. Lines are not followed across the repeat's top edge.
  double hole_lines = 0;
};

// A line of holes reaches over at least this many consecutive rows.
inline constexpr int kHoleLineRows = 3;

// Same preconditions as stitch_columns().
HoleLines hole_lines(const Chart& chart, int cast_on);

}  // namespace atelier::lace
