#include "algorithms/lace/fitness.h"

#include "algorithms/lace/hole_lines.h"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

namespace atelier::lace {

namespace {

// consumes() as a table: evaluate() runs for every child of every generation.
constexpr int kConsumes[] = {1, 0, 2, 2, 3, 3};  // k, yo, k2tog, ssk, sk2p, s2kp
int over(Symbol s) { return kConsumes[static_cast<int>(s)]; }

Symbol mirrored(Symbol s) {
  if (s == Symbol::k2tog) return Symbol::ssk;
  if (s == Symbol::ssk) return Symbol::k2tog;
  return s;
}

// Sum of max(0, run - 2) over the yarn-over runs of the row tiled with itself.
int adjacent_excess(const Row& row) {
  const int n = static_cast<int>(row.size());
  int start = -1;
  for (int i = 0; i < n; ++i) {
    if (row[i] != Symbol::yo) {
      start = i;
      break;
    }
  }
  if (start < 0) return n;  // nothing but yarn-overs: an unbounded run when repeated
  // Starting just after a non-yo cell, no run is cut by the row's end.
  int excess = 0, run = 0;
  for (int step = 1, i = start + 1; step <= n; ++step, ++i) {
    if (i == n) i = 0;
    if (row[i] == Symbol::yo) {
      ++run;
    } else {
      excess += std::max(0, run - kMaxAdjacentYarnOvers);
      run = 0;
    }
  }
  return excess + std::max(0, run - kMaxAdjacentYarnOvers);
}

}  // namespace

double weighted_sum(const Objectives& o, const Weights& w) {
  return w.holes * o.holes + w.knit_length * o.knit_length + w.depth * o.depth +
         w.symmetry * o.symmetry + w.hole_lines * o.hole_lines -
         w.yo_band * o.yo_band_distance - w.width_change * o.width_change;
}

double penalty(const Constraints& c, const Weights& w) {
  if (c.ok()) return 0.0;
  return (w.holes + w.knit_length + w.depth + w.symmetry + w.hole_lines + w.yo_band +
          w.width_change + 1.0) *
         (1.0 + c.total());
}

double score(const Constraints& c, const Objectives& o, const Weights& w) {
  return weighted_sum(o, w) - penalty(c, w);
}

Evaluation evaluate(const Chart& chart, int cast_on, const Weights& w, int width_tolerance) {
  if (chart.rows.empty()) throw std::invalid_argument("lace: evaluate: the chart has no rows");
  if (cast_on < 1) throw std::invalid_argument("lace: evaluate: cast_on must be >= 1");
  if (width_tolerance < 0) throw std::invalid_argument("lace: evaluate: width_tolerance must be >= 0");
  const int rows = static_cast<int>(chart.rows.size());
  for (int r = 0; r < rows; ++r) {
    if (chart.rows[r].empty()) {
      throw std::invalid_argument("lace: evaluate: row " + std::to_string(r) + " is empty");
    }
    int need = 0;
    for (Symbol x : chart.rows[r]) need += over(x);
    if (r > 0 && need != produced(chart.rows[r - 1])) {
      throw std::invalid_argument("lace: evaluate: row " + std::to_string(r) +
                                  " is not worked over the stitches row " + std::to_string(r - 1) +
                                  " makes");
    }
  }

  Evaluation e;
  Constraints& c = e.constraints;
  const int first = produced(chart.rows.front());
  int first_need = 0;
  for (Symbol x : chart.rows.front()) first_need += over(x);
  c.balance_error = std::abs(cast_on - first_need) +
                    std::abs(cast_on - produced(chart.rows.back()));

  long width_change = 0;  // sum over rows of |produced - cast_on|
  long cells = 0, yarn_overs = 0, plain = 0, plain_on_plain = 0, motif_cells = 0, mirror_matches = 0;
  for (int r = 0; r < rows; ++r) {
    const Row& row = chart.rows[r];
    const int n = produced(row);
    cells += n;
    width_change += std::abs(n - cast_on);
    c.adjacent_yo_excess += adjacent_excess(row);
    c.width_excess += std::max(0, std::abs(n - cast_on) - width_tolerance) +
                      std::max(0, std::abs(n - first) - width_tolerance);
    int below = 0;  // index in row r-1 of the first stitch the current symbol is worked over
    for (int j = 0; j < n; ++j) {
      const Symbol s = row[j];
      if (s == Symbol::yo) ++yarn_overs;
      if (s == Symbol::k) {
        ++plain;
        if (r > 0 && chart.rows[r - 1][below] == Symbol::k) ++plain_on_plain;
      }
      const Symbol mirror = mirrored(row[n - 1 - j]);
      if (s != Symbol::k || mirror != Symbol::k) {  // plain knitting is trivially symmetric
        ++motif_cells;
        if (s == mirror) ++mirror_matches;
      }
      below += over(s);
    }
  }

  // Depth: the tree (last-row stitch) each cell belongs to, propagated from the top down; going
  // down, the last non-plain cell seen for a tree is its deepest.
  std::vector<int> owner(chart.rows.back().size()), owner_below;
  for (std::size_t t = 0; t < owner.size(); ++t) owner[t] = static_cast<int>(t);
  std::vector<int> reach(owner.size(), 0);  // rows from the root to the deepest lace stitch, + 1
  for (int r = rows - 1; r >= 0; --r) {
    const Row& row = chart.rows[r];
    if (r > 0) owner_below.assign(chart.rows[r - 1].size(), 0);
    int below = 0;
    for (std::size_t j = 0; j < row.size(); ++j) {
      if (row[j] != Symbol::k) reach[owner[j]] = rows - r;
      if (r > 0) {
        for (int k = 0; k < over(row[j]); ++k) owner_below[below + k] = owner[j];
      }
      below += over(row[j]);
    }
    if (r > 0) owner.swap(owner_below);
  }
  long reach_sum = 0;
  for (int v : reach) reach_sum += v;

  Objectives& o = e.objectives;
  o.holes = std::min(1.0, 1.5 * static_cast<double>(yarn_overs) / static_cast<double>(cells));
  o.knit_length = plain == 0 ? 0.0
                             : static_cast<double>(plain) /
                                   static_cast<double>(plain - plain_on_plain) / rows;
  o.depth = static_cast<double>(reach_sum) / static_cast<double>(reach.size()) / rows;
  o.symmetry = motif_cells == 0 ? 0.0 : static_cast<double>(mirror_matches) / static_cast<double>(motif_cells);
  o.yo_share = static_cast<double>(yarn_overs) / static_cast<double>(cells);
  o.yo_band_distance = std::max(0.0, w.yo_share_min - o.yo_share) + std::max(0.0, o.yo_share - w.yo_share_max);
  o.width_change = std::min(1.0, static_cast<double>(width_change) / rows / cast_on);
  // The layout needs the stitches row 0 is worked over (a balance error may make that differ
  // from cast_on).
  if (first_need >= 1 && yarn_overs > 0) o.hole_lines = hole_lines(chart, first_need).hole_lines;
  e.score = score(c, o, w);
  return e;
}

}  // namespace atelier::lace
