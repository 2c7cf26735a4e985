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
  out.cast_on_columns.assign(static_cast<std::size_t>(cast_on), true);
  std::vector<int> below(static_cast<std::size_t>(cast_on));
  std::iota(below.begin(), below.end(), 0);  // the cast-on: a stitch in every column

  std::vector<int> items, stack, cells;
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
    // The row's cells: a paired free column is taken by its yarn-over.
    cells.clear();
    std::vector<int> added;  // columns an unpaired yarn-over adds
    for (std::size_t i = 0; i < items.size(); ++i) {
      if (items[i] == kFree && matched[i]) continue;
      if (is_yo(items[i]) && !matched[i]) added.push_back(static_cast<int>(cells.size()));
      cells.push_back(items[i]);
    }
    // Columns added by yarn-overs are no-stitch cells in every row below (left to right in
    // column order, so each insert lands where the items before it put it).
    for (int at : added) {
      for (auto& lower : out.cells) lower.insert(lower.begin() + at, -1);
      out.cast_on_columns.insert(out.cast_on_columns.begin() + at, false);
    }
    out.cells.push_back(cells);
    below = cells;
  }
  out.columns = static_cast<int>(below.size());
  out.column.resize(chart.rows.size());
  for (std::size_t r = 0; r < chart.rows.size(); ++r) {
    out.column[r].assign(chart.rows[r].size(), -1);
    for (std::size_t col = 0; col < out.cells[r].size(); ++col)
      if (out.cells[r][col] >= 0) out.column[r][static_cast<std::size_t>(out.cells[r][col])] = static_cast<int>(col);
  }
  return out;
}

}  // namespace atelier::lace
