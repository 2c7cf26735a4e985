// A lace knitting chart (Ekart 2007, section 2) and the paper's constraints on it.
//
// Conventions:
// - Only right-side rows are stored; the wrong-side rows between them are purled, one purl
//   per stitch, and omitted (they change neither stitch count nor order).
// - rows[0] is the first row knitted (the bottom chart row, "Row 1 (RS)").
// - Each row is listed in knitting order: right to left as a knitter reads the chart, so
//   rows[r][0] is the rightmost cell. Symbol j of row r is worked over the next consumes()
//   stitches of row r-1 in that same order (row 0 is worked over the cast-on stitches).
// - Widths are in stitches.
// Value types; pure functions, thread-safe.
#pragma once

#include <string>
#include <vector>

#include "algorithms/lace/symbols.h"

namespace atelier::lace {

using Row = std::vector<Symbol>;

struct Chart {
  std::vector<Row> rows;  // right-side rows, rows[0] first knitted, each in knitting order
  friend bool operator==(const Chart&, const Chart&) = default;
};

// Stitches the row makes (one per symbol).
int produced(const Row& row);
// Stitches of the row below that the row is worked over (sum of consumes()).
int consumed(const Row& row);

// Why a chart cannot be knitted from `cast_on` stitches: the first row at fault (0-based
// index into Chart::rows) and a message naming it as the knitter counts ("row 3 (chart
// row 3, RS) ..."). ok is true and bad_row is -1 when the chart is knittable.
struct Knittability {
  bool ok = true;
  int bad_row = -1;
  std::string why;
  explicit operator bool() const { return ok; }
};

// A chart is knittable from cast_on stitches when it has at least one row, cast_on >= 1, row 0
// consumes exactly cast_on and every row i > 0 consumes exactly what row i-1 produced. (Then
// no row is empty.) A chart with no rows, or cast_on < 1, is refused with bad_row -1.
Knittability knittable(const Chart& chart, int cast_on);

// Eq. 1 of the paper: |yo| = |k2tog| + |ssk| + 2|sk2p| over the whole chart, i.e. the last
// row is as wide as the cast-on (for a knittable chart).
bool yarn_over_balance(const Chart& chart);

// The longest run of yarn-overs side by side in the row. With `repeated`, the row is taken as
// tiled side by side with itself (a pattern repeat), so a run may wrap from its end to its
// start; a row of yarn-overs only then has an unbounded run, reported as
// std::numeric_limits<int>::max().
int max_adjacent_yarn_overs(const Row& row, bool repeated = false);

// The paper's limit: never more than two yarn-overs next to each other.
inline constexpr int kMaxAdjacentYarnOvers = 2;

// Every row of the chart keeps max_adjacent_yarn_overs(row, repeated) <= kMaxAdjacentYarnOvers.
bool adjacent_yarn_overs_ok(const Chart& chart, bool repeated = false);

// Every row's width (produced) is within +-tolerance stitches of the first row's width.
// An empty chart is trivially fine. tolerance < 0 throws std::invalid_argument.
bool width_ok(const Chart& chart, int tolerance);

}  // namespace atelier::lace
