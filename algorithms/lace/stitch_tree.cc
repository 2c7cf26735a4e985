#include "algorithms/lace/stitch_tree.h"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace atelier::lace {

namespace {

int children_of(const Node& n) { return n.cast_on ? 0 : consumes(n.symbol); }

// Walks one tree depth first, children in knitting order, calling visit(node, row) for every
// node (row -1 for cast-on leaves). Returns "" or what is wrong with the tree. `seen` is
// scratch space reused across trees.
template <typename Visit>
std::string walk(const Tree& tree, int rows, std::vector<char>& seen, Visit&& visit) {
  if (tree.nodes.empty()) return "has no nodes";
  seen.assign(tree.nodes.size(), 0);
  std::vector<std::pair<std::uint32_t, int>> stack{{0u, rows - 1}};
  std::size_t reached = 0;
  while (!stack.empty()) {
    const auto [index, row] = stack.back();
    stack.pop_back();
    if (seen[index]) return "reaches node " + std::to_string(index) + " twice";
    seen[index] = 1;
    ++reached;
    const Node& node = tree.nodes[index];
    if (row == -1 && !node.cast_on) {
      return "has a stitch below row 0 (node " + std::to_string(index) + "): it is deeper than " +
             std::to_string(rows) + " rows";
    }
    if (row >= 0 && node.cast_on) {
      return "has a cast-on stitch at row " + std::to_string(row) + " (node " +
             std::to_string(index) + "): it is shallower than " + std::to_string(rows) + " rows";
    }
    visit(node, row);
    const int n = children_of(node);
    if (n == 0) continue;
    if (node.first_child <= index || node.first_child + n > tree.nodes.size()) {
      return "node " + std::to_string(index) + " has children outside [" +
             std::to_string(index + 1) + ", " + std::to_string(tree.nodes.size()) + ")";
    }
    for (int c = n - 1; c >= 0; --c) stack.emplace_back(node.first_child + c, row - 1);
  }
  if (reached != tree.nodes.size()) {
    return "has " + std::to_string(tree.nodes.size() - reached) + " nodes not reached from the root";
  }
  return "";
}

template <typename Visit>
std::string walk_all(const Forest& forest, Visit&& visit) {
  if (forest.rows < 1) return "a forest spans at least 1 row, got " + std::to_string(forest.rows);
  if (forest.trees.empty()) return "a forest has at least one tree";
  std::vector<char> seen;
  int leaves = 0;
  for (std::size_t t = 0; t < forest.trees.size(); ++t) {
    std::string err = walk(forest.trees[t], forest.rows, seen, [&](const Node& n, int row) {
      if (n.cast_on) ++leaves;
      visit(n, row);
    });
    if (!err.empty()) return "tree " + std::to_string(t) + " " + err;
  }
  if (leaves == 0) return "the trees stand on no cast-on stitch";
  return "";
}

}  // namespace

Forest encode(const Chart& chart, int cast_on) {
  if (const Knittability k = knittable(chart, cast_on); !k) {
    throw std::invalid_argument("lace: cannot encode the chart: " + k.why);
  }
  const int rows = static_cast<int>(chart.rows.size());
  // first_below[r][j]: index in row r-1 (or the cast-on) of the first stitch symbol j of row
  // r is worked over.
  std::vector<std::vector<int>> first_below(rows);
  for (int r = 0; r < rows; ++r) {
    first_below[r].reserve(chart.rows[r].size());
    int at = 0;
    for (Symbol s : chart.rows[r]) {
      first_below[r].push_back(at);
      at += consumes(s);
    }
  }
  Forest forest;
  forest.rows = rows;
  forest.trees.reserve(chart.rows.back().size());
  std::vector<std::pair<int, int>> where;  // (row, index in row) of each node, breadth first
  for (int root = 0; root < static_cast<int>(chart.rows.back().size()); ++root) {
    Tree tree;
    where.assign(1, {rows - 1, root});
    for (std::size_t i = 0; i < where.size(); ++i) {
      const auto [row, j] = where[i];
      Node node;
      if (row < 0) {
        node.cast_on = true;
      } else {
        node.symbol = chart.rows[row][j];
        node.first_child = static_cast<std::uint32_t>(where.size());
        const int n = consumes(node.symbol);
        for (int c = 0; c < n; ++c) where.emplace_back(row - 1, first_below[row][j] + c);
        if (n == 0) node.first_child = 0;
      }
      tree.nodes.push_back(node);
    }
    forest.trees.push_back(std::move(tree));
  }
  return forest;
}

std::string forest_error(const Forest& forest) {
  return walk_all(forest, [](const Node&, int) {});
}

Chart decode(const Forest& forest) {
  Chart chart;
  chart.rows.resize(std::max(forest.rows, 0));
  const std::string err = walk_all(forest, [&](const Node& n, int row) {
    if (row >= 0) chart.rows[row].push_back(n.symbol);
  });
  if (!err.empty()) throw std::invalid_argument("lace: cannot decode the trees: " + err);
  return chart;
}

int cast_on(const Forest& forest) {
  int leaves = 0;
  for (const Tree& tree : forest.trees) {
    for (const Node& n : tree.nodes) leaves += n.cast_on ? 1 : 0;
  }
  return leaves;
}

int depth(const Forest& forest) {
  int deepest = 0;
  std::vector<int> height;  // stitch levels from a node down to its deepest leaf
  for (const Tree& tree : forest.trees) {
    if (tree.nodes.empty()) continue;
    height.assign(tree.nodes.size(), 0);
    // Children come after their parent, so a reverse sweep sees every child first.
    for (std::size_t i = tree.nodes.size(); i-- > 0;) {
      const Node& node = tree.nodes[i];
      if (node.cast_on) continue;
      int below = 0;
      const std::size_t n = children_of(node);
      // Malformed child ranges are skipped: depth() measures, forest_error() judges.
      if (n > 0 && node.first_child > i && node.first_child + n <= tree.nodes.size()) {
        for (std::size_t c = 0; c < n; ++c) below = std::max(below, height[node.first_child + c]);
      }
      height[i] = below + 1;
    }
    deepest = std::max(deepest, height[0]);
  }
  return deepest;
}

}  // namespace atelier::lace
