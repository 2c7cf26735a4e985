// The printed layout of a lace chart (algorithms/lace/chart_layout.h, issue 22 lace point 1):
// equal-width rows, each stitch over the stitches it is worked into, grey "no stitch" cells
// where a decrease is not yet balanced by a yarn-over (or the other way round).
#include <gtest/gtest.h>

#include <cstdlib>
#include <random>
#include <utility>
#include <stdexcept>
#include <string>
#include <vector>

#include "algorithms/lace/chart_layout.h"
#include "algorithms/lace/random_chart.h"
#include "tests/support/lace_test_charts.h"
#include "tests/unit/algorithms/lace/chart_fixture.h"

namespace atelier::lace {
namespace {

using namespace test;  // row(), knit() and the charts of lace_test_charts.h

// The columns of the stitches of `row` (0-based) are worked into: the row below's columns, or
// the cast-on columns for row 0.
std::vector<std::vector<int>> worked_into(const ChartLayout& l, const Chart& c, std::size_t r) {
  std::vector<int> below;
  for (int col = 0; col < l.columns; ++col) {
    if (r == 0 ? static_cast<bool>(l.cast_on_columns[static_cast<std::size_t>(col)])
               : l.cells[r - 1][static_cast<std::size_t>(col)] >= 0)
      below.push_back(col);
  }
  std::vector<std::vector<int>> out;
  std::size_t p = 0;
  for (Symbol s : c.rows[r]) {
    out.emplace_back(below.begin() + static_cast<long>(p), below.begin() + static_cast<long>(p + consumes(s)));
    p += static_cast<std::size_t>(consumes(s));
  }
  return out;
}

// What every layout keeps: rows of one width, each row's stitches in order in its cells, and a
// row with no yarn-over puts each stitch exactly over the stitch that ends on top of it.
void expect_well_formed(const Chart& c, int cast_on) {
  const ChartLayout l = layout_chart(c, cast_on);
  ASSERT_EQ(l.cells.size(), c.rows.size());
  ASSERT_EQ(static_cast<int>(l.cast_on_columns.size()), l.columns);
  for (std::size_t r = 0; r < c.rows.size(); ++r) {
    ASSERT_EQ(static_cast<int>(l.cells[r].size()), l.columns) << "row " << 2 * r + 1;
    int next = 0, yos = 0;
    for (int cell : l.cells[r])
      if (cell >= 0) EXPECT_EQ(cell, next++) << "row " << 2 * r + 1;
    EXPECT_EQ(next, produced(c.rows[r]));
    for (Symbol s : c.rows[r]) yos += s == Symbol::yo;
    const auto into = worked_into(l, c, r);
    for (std::size_t j = 0; j < c.rows[r].size(); ++j) {
      const Symbol s = c.rows[r][j];
      if (s == Symbol::yo) continue;
      const int want = into[j][static_cast<std::size_t>(top_stitch(s))];
      if (yos == 0) EXPECT_EQ(l.column[r][j], want) << "row " << 2 * r + 1 << " stitch " << j + 1;
      // A yarn-over balancing a decrease in the row shifts the stitches between by one column.
      EXPECT_LE(std::abs(l.column[r][j] - want), yos) << "row " << 2 * r + 1 << " stitch " << j + 1;
    }
  }
}

// Decreases first, their yarn-overs a row later (7 -> 5 -> 7 stitches): row 1 has a no-stitch
// cell beside each k2tog, and row 3's yarn-overs sit in exactly those columns.
TEST(LaceChartLayout, DecreasesBeforeTheirYarnOversLeaveNoStitchCells) {
  const Chart c{{row({"k", "k2tog", "k", "k2tog", "k"}), row({"k", "yo", "k", "k", "yo", "k", "k"}), knit(7)}};
  const ChartLayout l = layout_chart(c, 7);
  EXPECT_EQ(l.columns, 7);
  EXPECT_EQ(l.cells[0], (std::vector<int>{0, -1, 1, 2, -1, 3, 4}));  // k2tog over its left (top) stitch
  EXPECT_EQ(l.cells[1], (std::vector<int>{0, 1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(l.cells[2], (std::vector<int>{0, 1, 2, 3, 4, 5, 6}));
  // Every plain stitch of rows 3 and 5 sits in the column of the stitch it is worked into.
  EXPECT_EQ(l.column[1], (std::vector<int>{0, 1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(worked_into(l, c, 1)[2], (std::vector<int>{2}));
  EXPECT_EQ(worked_into(l, c, 1)[1], (std::vector<int>{}));  // the yo: over the no-stitch cell
  expect_well_formed(c, 7);
}

// The other way round: a yarn-over whose decrease comes a row later adds a column; the rows
// below it get a no-stitch cell there and the decrease's row one beside the k2tog.
TEST(LaceChartLayout, YarnOversBeforeTheirDecreasesAddAColumn) {
  const Chart c{{knit(3), row({"k", "yo", "k", "k"}), row({"k", "k2tog", "k"})}};
  const ChartLayout l = layout_chart(c, 3);
  EXPECT_EQ(l.columns, 4);
  EXPECT_EQ(l.cells[0], (std::vector<int>{0, -1, 1, 2}));
  EXPECT_EQ(l.cells[1], (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(l.cells[2], (std::vector<int>{0, -1, 1, 2}));
  EXPECT_EQ(l.cast_on_columns, (std::vector<bool>{true, false, true, true}));
  expect_well_formed(c, 3);
}

// Rows that balance themselves need no no-stitch cell: classic charts stay as printed.
TEST(LaceChartLayout, BalancedRowsHaveNoNoStitchCells) {
  for (const auto& [c, w] : {std::pair{horseshoe_chart(), 10}, {feather_and_fan_chart(), 18}, {eyelet_chart(), 8}}) {
    const ChartLayout l = layout_chart(c, w);
    EXPECT_EQ(l.columns, w);
    for (const auto& cells : l.cells)
      for (int cell : cells) EXPECT_GE(cell, 0);
    expect_well_formed(c, w);
  }
}

// Evolved-like charts (random feasible, rows 10-13 wide): every layout is well formed and all
// rows are equally wide.
TEST(LaceChartLayout, RandomChartsLineUp) {
  std::mt19937_64 rng(22);
  for (int i = 0; i < 40; ++i) {
    const Chart c = random_feasible_chart(12, 8, rng);
    expect_well_formed(c, consumed(c.rows[0]));
  }
}

TEST(LaceChartLayout, UnknittableChartIsRefused) {
  EXPECT_THROW(layout_chart(Chart{{row({"k", "k2tog"})}}, 5), std::invalid_argument);
  EXPECT_THROW(layout_chart(Chart{}, 5), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::lace
