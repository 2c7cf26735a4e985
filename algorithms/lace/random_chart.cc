#include "algorithms/lace/random_chart.h"

#include <cstdint>
#include <stdexcept>
#include <utility>
#include <vector>

namespace atelier::lace {

namespace {

// Expected stitches below a drawn stitch: 0.63*1 + 0.2*0 + 0.07*2 + 0.07*2 + 0.03*3 = 1.0.
// Yarn-overs balance the decreases on average (0.2 = 0.07 + 0.07 + 2*0.03), as eq. 1 wants.
Symbol draw_symbol(std::mt19937_64& rng, bool allow_decreases) {
  std::uniform_int_distribution<int> d(0, 99);
  const int x = d(rng);
  if (!allow_decreases) return x < 75 ? Symbol::k : Symbol::yo;
  if (x < 63) return Symbol::k;
  if (x < 83) return Symbol::yo;
  if (x < 90) return Symbol::k2tog;
  if (x < 97) return Symbol::ssk;
  return Symbol::s2kp;  // the centred double decrease (issue 22)
}

constexpr int kMaxLevelWidth = 6;

}  // namespace

Tree random_tree(int row, std::mt19937_64& rng) {
  if (row < 0) throw std::invalid_argument("lace: random_tree: row must be >= 0");
  Tree tree;
  tree.nodes.emplace_back();
  // Breadth first, one level at a time: [begin, end) is the current level, all at `level`.
  std::size_t begin = 0, end = 1;
  for (int level = row; begin < end; --level) {
    int next_width = 0;
    for (std::size_t i = begin; i < end; ++i) {
      Node& node = tree.nodes[i];
      if (level < 0) {
        node.cast_on = true;
        continue;
      }
      node.symbol = draw_symbol(rng, next_width < kMaxLevelWidth);
      const int n = consumes(node.symbol);
      // tree.nodes may reallocate below: write through the index, not the reference.
      tree.nodes[i].first_child = n == 0 ? 0u : static_cast<std::uint32_t>(tree.nodes.size());
      tree.nodes.resize(tree.nodes.size() + n);
      next_width += n;
    }
    begin = end;
    end = tree.nodes.size();
  }
  return tree;
}

Forest random_forest(int width, int rows, std::mt19937_64& rng) {
  if (width < 1 || rows < 1) throw std::invalid_argument("lace: random_forest: width and rows must be >= 1");
  Forest forest;
  forest.rows = rows;
  forest.trees.reserve(width);
  bool grounded = false;
  for (int t = 0; t < width; ++t) {
    forest.trees.push_back(random_tree(rows - 1, rng));
    for (const Node& n : forest.trees.back().nodes) grounded = grounded || n.cast_on;
  }
  // A forest must stand on at least one cast-on stitch: redraw the last tree until it does.
  while (!grounded) {
    forest.trees.back() = random_tree(rows - 1, rng);
    for (const Node& n : forest.trees.back().nodes) grounded = grounded || n.cast_on;
  }
  return forest;
}

Chart random_feasible_chart(int width, int rows, std::mt19937_64& rng, bool carriage_pairings) {
  if (width < 1 || rows < 1) {
    throw std::invalid_argument("lace: random_feasible_chart: width and rows must be >= 1");
  }
  // Every unit is as wide as it consumes, and a unit holds a yarn-over only at its ends with a
  // decrease between them, so at most two units' ends ever touch: runs of at most 2.
  std::uniform_int_distribution<int> d(0, 99);
  Chart chart;
  chart.rows.resize(rows);
  for (Row& row : chart.rows) {
    row.reserve(width);
    while (static_cast<int>(row.size()) < width) {
      const int left = width - static_cast<int>(row.size());
      const int x = d(rng);
      if (x < 12 && left >= 3) {
        // The centred s2kp needs its centre stitch on top, but on a lace carriage the stitch
        // already on the needle stays at the bottom: the carriage makes the left-leaning sk2p.
        row.insert(row.end(), {Symbol::yo, carriage_pairings ? Symbol::sk2p : Symbol::s2kp, Symbol::yo});
      } else if (x < 20 && left >= 2) {
        // A lace carriage lays the moved stitch on top, so it can make "k2tog, yo" and
        // "yo, ssk" but not these two (transfers.h); the same draw then gives the mirror.
        if (carriage_pairings) row.insert(row.end(), {Symbol::k2tog, Symbol::yo});
        else row.insert(row.end(), {Symbol::yo, Symbol::k2tog});
      } else if (x < 28 && left >= 2) {
        if (carriage_pairings) row.insert(row.end(), {Symbol::yo, Symbol::ssk});
        else row.insert(row.end(), {Symbol::ssk, Symbol::yo});
      } else if (x < 34 && left >= 2) {
        row.insert(row.end(), {Symbol::k2tog, Symbol::yo});
      } else if (x < 40 && left >= 2) {
        row.insert(row.end(), {Symbol::yo, Symbol::ssk});
      } else {
        row.push_back(Symbol::k);
      }
    }
  }
  return chart;
}

namespace {

// One mirror-symmetric row (random_symmetric_chart()); a row whose yarn-overs meet in threes
// (the halves' edge runs touch in the middle and across the repeat edge) is drawn again, at
// most 100 times, then it is plain.
Row symmetric_row(int width, std::mt19937_64& rng) {
  const int half = width / 2;
  for (int attempt = 0; attempt < 100 && half > 0; ++attempt) {
    const Row right = random_feasible_chart(half, 1, rng).rows.front();
    Row row = right;
    if (width % 2 == 1) row.push_back(Symbol::k);
    for (auto it = right.rbegin(); it != right.rend(); ++it) {
      row.push_back(*it == Symbol::k2tog ? Symbol::ssk : *it == Symbol::ssk ? Symbol::k2tog : *it);
    }
    if (max_adjacent_yarn_overs(row, true) <= kMaxAdjacentYarnOvers) return row;
  }
  return Row(width, Symbol::k);
}

}  // namespace

Chart random_symmetric_chart(int width, int rows, std::mt19937_64& rng) {
  if (width < 1 || rows < 1) {
    throw std::invalid_argument("lace: random_symmetric_chart: width and rows must be >= 1");
  }
  Chart chart;
  chart.rows.reserve(rows);
  for (int r = 0; r < rows; ++r) chart.rows.push_back(symmetric_row(width, rng));
  return chart;
}

}  // namespace atelier::lace
