// The chart as lace charts are printed (issue 22, lace point 1): a grid of cells in which
// every row has the same number of columns, each stitch sits over the stitches it is worked
// into, and grey "no stitch" cells fill the columns a row does not use.
//
// The convention (pattern books, Stitchmastery-style charts): columns are stitch positions.
// - A plain stitch sits in the column of the stitch it is worked into.
// - A decrease sits in the column of the stitch that ends up on top (k2tog: the left one of
//   its 2, ssk: the right one, s2kp: the centre, sk2p: the right one); the other columns it
//   is worked over are freed.
// - A yarn-over needs a column. Within a row it takes the nearest freed column (a decrease
//   earlier or later in the same row, or a no-stitch cell of the row below): the stitches
//   between them shift one column toward the decrease, as in every printed lace chart where a
//   yarn-over balances a decrease a few stitches away.
// - A freed column no yarn-over of the row takes is a no-stitch cell in this row (a decrease
//   not yet balanced); it stays no-stitch upward until a yarn-over takes it.
// - A yarn-over with no freed column left in its row adds a column: the rows below get a
//   no-stitch cell there (a yarn-over that a decrease of a later row balances).
// So a stitch is at most as many columns away from the stitches it is worked into as there are
// yarn-over / decrease pairs of its row around it, and none when its row has none.
//
// Columns are counted in knitting order: column 0 is the RIGHT edge of the printed chart
// (chart.h), like Row indices. Pure functions, value types, thread-safe. Bounded: the work is
// O(rows * columns), columns <= cast_on + the chart's yarn-overs.
#pragma once

#include <optional>
#include <vector>

#include "algorithms/lace/chart.h"

namespace atelier::lace {

struct ChartLayout {
  int columns = 0;  // every row's width in cells
  // cells[r][c]: the index into Chart::rows[r] of the stitch in column c, or -1 for a
  // "no stitch" cell. Each row lists its stitches in order: the non-negative entries of
  // cells[r] are 0, 1, ..., produced(row) - 1.
  std::vector<std::vector<int>> cells;
  // cast_on_columns[c]: whether column c holds a cast-on stitch (false: a column a yarn-over
  // added above, no stitch in the cast-on).
  std::vector<bool> cast_on_columns;
  // column[r][j]: the column of stitch j of row r (the inverse of cells).
  std::vector<std::vector<int>> column;
};

// The printed layout of a chart knittable from cast_on stitches. Throws std::invalid_argument
// with knittable()'s reason otherwise.
ChartLayout layout_chart(const Chart& chart, int cast_on);

}  // namespace atelier::lace
