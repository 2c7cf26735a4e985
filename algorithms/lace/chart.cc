#include "algorithms/lace/chart.h"

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <stdexcept>

namespace atelier::lace {

int produced(const Row& row) { return static_cast<int>(row.size()); }

int consumed(const Row& row) {
  int n = 0;
  for (Symbol s : row) n += consumes(s);
  return n;
}

namespace {

// The knitter's numbering: stored RS row i is knitted as row 2i+1 (WS rows are even).
std::string row_label(std::size_t i) {
  return "row " + std::to_string(i) + " (knitted as row " + std::to_string(2 * i + 1) + ", RS)";
}

}  // namespace

Knittability knittable(const Chart& chart, int cast_on) {
  if (chart.rows.empty()) return {false, -1, "the chart has no rows"};
  if (cast_on < 1) {
    return {false, -1, "the cast-on must be at least 1 stitch, got " + std::to_string(cast_on)};
  }
  int available = cast_on;
  for (std::size_t i = 0; i < chart.rows.size(); ++i) {
    const int need = consumed(chart.rows[i]);
    if (need != available) {
      const std::string below = i == 0 ? "the cast-on has " : "the row below makes ";
      return {false, static_cast<int>(i),
              row_label(i) + " is worked over " + std::to_string(need) + " stitches but " + below +
                  std::to_string(available)};
    }
    available = produced(chart.rows[i]);
  }
  return {};
}

bool yarn_over_balance(const Chart& chart) {
  long increases = 0, decreases = 0;
  for (const Row& row : chart.rows) {
    for (Symbol s : row) {
      if (s == Symbol::yo) ++increases;
      else decreases += consumes(s) - 1;  // k2tog, ssk: 1; sk2p: 2; k: 0
    }
  }
  return increases == decreases;
}

int max_adjacent_yarn_overs(const Row& row, bool repeated) {
  int best = 0, run = 0;
  for (Symbol s : row) {
    run = s == Symbol::yo ? run + 1 : 0;
    best = std::max(best, run);
  }
  if (!repeated || row.empty()) return best;
  if (best == static_cast<int>(row.size())) return std::numeric_limits<int>::max();
  // Tiled: the trailing run of one repeat touches the leading run of the next.
  const auto lead = std::find_if(row.begin(), row.end(), [](Symbol s) { return s != Symbol::yo; }) -
                    row.begin();
  const auto trail =
      std::find_if(row.rbegin(), row.rend(), [](Symbol s) { return s != Symbol::yo; }) - row.rbegin();
  return std::max(best, static_cast<int>(lead + trail));
}

bool adjacent_yarn_overs_ok(const Chart& chart, bool repeated) {
  return std::all_of(chart.rows.begin(), chart.rows.end(), [&](const Row& row) {
    return max_adjacent_yarn_overs(row, repeated) <= kMaxAdjacentYarnOvers;
  });
}

bool width_ok(const Chart& chart, int tolerance) {
  if (tolerance < 0) throw std::invalid_argument("lace: width tolerance must be >= 0");
  if (chart.rows.empty()) return true;
  const int first = produced(chart.rows.front());
  return std::all_of(chart.rows.begin(), chart.rows.end(), [&](const Row& row) {
    return std::abs(produced(row) - first) <= tolerance;
  });
}

}  // namespace atelier::lace
