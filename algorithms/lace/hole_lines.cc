#include "algorithms/lace/hole_lines.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace atelier::lace {

std::vector<std::vector<double>> stitch_columns(const Chart& chart, int cast_on) {
  if (cast_on < 1) throw std::invalid_argument("lace: stitch_columns: cast_on must be >= 1");
  std::vector<std::vector<double>> columns(chart.rows.size());
  std::vector<double> below(cast_on);
  for (int i = 0; i < cast_on; ++i) below[i] = i;
  for (std::size_t r = 0; r < chart.rows.size(); ++r) {
    const Row& row = chart.rows[r];
    if (consumed(row) != static_cast<int>(below.size())) {
      throw std::invalid_argument("lace: stitch_columns: row " + std::to_string(r) +
                                  " is not worked over the stitches below it");
    }
    std::vector<double>& out = columns[r];
    out.reserve(row.size());
    std::size_t b = 0;  // next stitch of the row below
    for (Symbol s : row) {
      const int c = consumes(s);
      if (c == 0) {
        if (below.empty()) out.push_back(0.0);
        else if (b == 0) out.push_back(below.front() - 0.5);
        else if (b == below.size()) out.push_back(below.back() + 0.5);
        else out.push_back(0.5 * (below[b - 1] + below[b]));
      } else {
        double sum = 0;
        for (int k = 0; k < c; ++k) sum += below[b + k];
        out.push_back(sum / c);
      }
      b += c;
    }
    below = out;
  }
  return columns;
}

HoleLines hole_lines(const Chart& chart, int cast_on) {
  const std::vector<std::vector<double>> columns = stitch_columns(chart, cast_on);
  const double period = cast_on;
  auto near = [&](double a, double b) {
    double d = std::fmod(std::abs(a - b), period);
    d = std::min(d, period - d);
    return d <= kHoleLineReach + 1e-9;
  };
  // Whether row r has a hole within reach of column x (rows of a chart are short: linear scan).
  auto hole_near = [&](std::size_t r, double x) {
    const Row& row = chart.rows[r];
    for (std::size_t j = 0; j < row.size(); ++j) {
      if (row[j] == Symbol::yo && near(columns[r][j], x)) return true;
    }
    return false;
  };
  HoleLines h;
  // The holes, row by row (first[r] = index of row r's first hole), joined into lines by
  // union-find; each line remembers its lowest and highest row.
  struct Hole {
    int row;
    double x;
  };
  std::vector<Hole> holes;
  std::vector<std::size_t> first(chart.rows.size() + 1, 0);
  for (std::size_t r = 0; r < chart.rows.size(); ++r) {
    const Row& row = chart.rows[r];
    first[r] = holes.size();
    h.cells += static_cast<long>(row.size());
    for (std::size_t j = 0; j < row.size(); ++j) {
      if (row[j] != Symbol::yo) continue;
      holes.push_back({static_cast<int>(r), columns[r][j]});
      const double x = columns[r][j];
      if ((r > 0 && hole_near(r - 1, x)) || (r + 1 < chart.rows.size() && hole_near(r + 1, x))) ++h.connected;
    }
  }
  first[chart.rows.size()] = holes.size();
  h.yarn_overs = static_cast<long>(holes.size());
  std::vector<std::size_t> parent(holes.size());
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto root = [&](std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (std::size_t r = 0; r + 1 < chart.rows.size(); ++r) {
    for (std::size_t a = first[r]; a < first[r + 1]; ++a) {
      for (std::size_t b = first[r + 1]; b < first[r + 2]; ++b) {
        if (near(holes[a].x, holes[b].x)) parent[root(a)] = root(b);
      }
    }
  }
  std::vector<int> lo(holes.size(), 1 << 30), hi(holes.size(), -1);
  for (std::size_t i = 0; i < holes.size(); ++i) {
    const std::size_t top = root(i);
    lo[top] = std::min(lo[top], holes[i].row);
    hi[top] = std::max(hi[top], holes[i].row);
  }
  for (std::size_t i = 0; i < holes.size(); ++i) {
    const std::size_t top = root(i);
    if (hi[top] - lo[top] + 1 >= kHoleLineRows) ++h.in_lines;
  }
  h.hole_lines = holes.empty() ? 0.0 : static_cast<double>(h.in_lines) / static_cast<double>(holes.size());
  h.yo_share = h.cells == 0 ? 0.0 : static_cast<double>(h.yarn_overs) / static_cast<double>(h.cells);
  h.connectedness = h.yarn_overs == 0 ? 0.0 : static_cast<double>(h.connected) / static_cast<double>(h.yarn_overs);
  return h;
}

}  // namespace atelier::lace
