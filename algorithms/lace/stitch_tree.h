// The genotype of Ekart 2007 (section 3, Fig. 3 and 5): a lace chart as an ordered set of
// trees, one tree per stitch of the chart's last row.
//
// A node is a stitch: its Symbol, made over its children, the stitches of the row below that
// it is worked over, in knitting order (k: 1 child, yo: none, k2tog/ssk: 2, sk2p: 3). The root
// of tree t is stitch t of the last row (knitting order, see chart.h). A node at chart row r
// has its children at row r-1; the children of a row-0 stitch are cast-on leaves.
//
// Cast-on leaves: a Node with cast_on = true stands for one cast-on stitch (the needle's
// stitches before row 0). It has no symbol (the field is ignored) and no children, and it only
// ever appears one level below row 0. So every path from a root ends either at a yarn-over
// (which is worked over nothing, in any row) or at a cast-on leaf exactly `rows` stitch levels
// down: that is what "full depth" means here, and why all trees of a chart share one depth.
//
// Layout: each tree owns its nodes; nodes[0] is the root and the children of a node are the
// contiguous run nodes[first_child, first_child + consumes(symbol)), after the node itself
// (first_child > the node's index). encode() writes trees in breadth-first order; decode()
// accepts any such layout. Value types; pure functions, thread-safe.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/symbols.h"

namespace atelier::lace {

struct Node {
  bool cast_on = false;       // a cast-on stitch (leaf below row 0); symbol is then ignored
  Symbol symbol = Symbol::k;  // the stitch made here
  std::uint32_t first_child = 0;  // index in Tree::nodes of the first child; unused when the
                                  // node has no children (yo, cast-on leaf)
  friend bool operator==(const Node&, const Node&) = default;
};

struct Tree {
  std::vector<Node> nodes;  // nodes[0] is the root: one stitch of the last row
  friend bool operator==(const Tree&, const Tree&) = default;
};

struct Forest {
  int rows = 0;             // chart rows (right-side rows) the trees span
  std::vector<Tree> trees;  // one per stitch of the last row, in knitting order
  friend bool operator==(const Forest&, const Forest&) = default;
};

// The trees of a knittable chart (unique for a chart and its cast-on). Throws
// std::invalid_argument with knittable()'s reason when the chart cannot be knitted from
// cast_on stitches.
Forest encode(const Chart& chart, int cast_on);

// Why the forest is not a well-formed full-depth forest, or "" when it is: rows >= 1, at least
// one tree, every node reached exactly once from its root, children after their parent and
// inside the tree, cast-on leaves exactly one level below row 0 and nowhere else, at least one
// cast-on stitch in all.
std::string forest_error(const Forest& forest);

// The chart the trees describe: row r is the row-r stitches of tree 0, then tree 1, ..., each
// tree's read left to right. Any well-formed forest gives a chart that is knittable from
// cast_on(forest) stitches, by construction. Throws std::invalid_argument with forest_error()
// for a malformed forest.
Chart decode(const Forest& forest);

// Cast-on stitches the trees stand on (their cast-on leaves).
int cast_on(const Forest& forest);

// The trees' depth counted in stitch rows: the longest root-to-leaf path, cast-on leaves not
// counted. For a well-formed forest this equals forest.rows (some path reaches the cast-on).
int depth(const Forest& forest);

}  // namespace atelier::lace
