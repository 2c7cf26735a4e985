#include "algorithms/lace/chart_layout.h"

#include <numeric>
#include <stdexcept>

namespace atelier::lace {

namespace {

constexpr int kFree = -1;  // an item for a column no stitch of the row sits in (yet)

}  // namespace

ChartLayout layout_chart(const Chart& chart, int cast_on) {
  if (const Knittability k = knittable(chart, cast_on); !k)
    throw std::invalid_argument("lace chart layout: " + k.why);
  ChartLayout out;
  out.cells.reserve(chart.rows.size());
  std::vector<std::vector<int>> added;  // per row: columns (of its own cells) it adds
  added.reserve(chart.rows.size());
  std::vector<int> below(static_cast<std::size_t>(cast_on));
  std::iota(below.begin(), below.end(), 0);  // the cast-on: a stitch in every column

  std::vector<int> items, stack;
  std::vector<char> matched;
  for (const Row& row : chart.rows) {
    // The row's items in knitting order: each stitch of the row (its index) and a kFree for
    // every column of the row below that no stitch of this row sits over. A yarn-over is an
    // item with no column of its own.
    items.clear();
    std::size_t c = 0;
    for (std::size_t j = 0; j < row.size(); ++j) {
      const int n = consumes(row[j]);
      const int top = top_stitch(row[j]);
      for (int i = 0; i < n; ++i) {
        while (below[c] < 0) items.push_back(kFree), ++c;  // a no-stitch cell below
        items.push_back(i == top ? static_cast<int>(j) : kFree);
        ++c;
      }
      if (n == 0) items.push_back(static_cast<int>(j));
    }
    for (; c < below.size(); ++c) items.push_back(kFree);  // no-stitch cells at the left end

    // Pair each yarn-over with the nearest free column of the row (bracket matching: pairs
    // never cross, so an unpaired item never lies between a pair).
    auto is_yo = [&](int item) { return item >= 0 && row[static_cast<std::size_t>(item)] == Symbol::yo; };
    matched.assign(items.size(), 0);
    stack.clear();
    for (std::size_t i = 0; i < items.size(); ++i) {
      const bool yo = is_yo(items[i]);
      if (!yo && items[i] != kFree) continue;
      if (!stack.empty() && is_yo(items[static_cast<std::size_t>(stack.back())]) != yo) {
        matched[static_cast<std::size_t>(stack.back())] = matched[i] = 1;
        stack.pop_back();
      } else {
        stack.push_back(static_cast<int>(i));
      }
    }
    // The row's cells: a paired free column is taken by its yarn-over. An unpaired yarn-over
    // adds a column; it is recorded and put into the rows below at the end.
    std::vector<int>& row_cells = out.cells.emplace_back();
    std::vector<int>& row_added = added.emplace_back();
    for (std::size_t i = 0; i < items.size(); ++i) {
      if (items[i] == kFree && matched[i]) continue;
      if (is_yo(items[i]) && !matched[i]) row_added.push_back(static_cast<int>(row_cells.size()));
      row_cells.push_back(items[i]);
    }
    below = row_cells;
  }
  // Columns added by yarn-overs are no-stitch cells in every row below. Top down: to_final
  // maps a column of row r (its own cells) to the final column; the row below's columns are
  // row r's minus the ones row r added. O(rows * columns) in all.
  out.columns = static_cast<int>(below.size());
  std::vector<int> to_final(below.size()), next;
  std::iota(to_final.begin(), to_final.end(), 0);
  std::vector<char> is_added;
  for (std::size_t r = chart.rows.size(); r-- > 0;) {
    std::vector<int>& cells = out.cells[r];
    std::vector<int> wide(static_cast<std::size_t>(out.columns), -1);
    for (std::size_t col = 0; col < cells.size(); ++col) wide[static_cast<std::size_t>(to_final[col])] = cells[col];
    cells = std::move(wide);
    // The columns of the row below (row r - 1, or the cast-on) in final columns.
    is_added.assign(to_final.size(), 0);
    for (int at : added[r]) is_added[static_cast<std::size_t>(at)] = 1;
    next.clear();
    for (std::size_t col = 0; col < to_final.size(); ++col)
      if (!is_added[col]) next.push_back(to_final[col]);
    to_final.swap(next);
  }
  out.cast_on_columns.assign(static_cast<std::size_t>(out.columns), false);
  for (int col : to_final) out.cast_on_columns[static_cast<std::size_t>(col)] = true;
  out.column.resize(chart.rows.size());
  for (std::size_t r = 0; r < chart.rows.size(); ++r) {
    out.column[r].assign(chart.rows[r].size(), -1);
    for (std::size_t col = 0; col < out.cells[r].size(); ++col)
      if (out.cells[r][col] >= 0) out.column[r][static_cast<std::size_t>(out.cells[r][col])] = static_cast<int>(col);
  }
  return out;
}

}  // namespace atelier::lace
