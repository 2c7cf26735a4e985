#include "algorithms/lace/operators.h"

#include <cstdint>
#include <utility>
#include <vector>

#include "algorithms/lace/random_chart.h"

namespace atelier::lace {

namespace {

// consumes() as a table: this runs for every node of every child, every generation.
constexpr int kConsumes[] = {1, 0, 2, 2, 3, 3};  // k, yo, k2tog, ssk, sk2p, s2kp
int children_of(const Node& n) { return n.cast_on ? 0 : kConsumes[static_cast<int>(n.symbol)]; }

std::size_t pick(std::size_t n, std::mt19937_64& rng) {
  return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng);
}

// The node range [begin, end) of chart row `row` in a tree laid out breadth first (every level
// contiguous, as all trees here are); empty when the tree has no stitch that deep.
std::pair<std::uint32_t, std::uint32_t> level_range(const Tree& tree, int rows, int row) {
  std::uint32_t begin = 0, end = 1;
  for (int level = rows - 1; level > row && begin < end; --level) {
    std::uint32_t below = 0;
    for (std::uint32_t i = begin; i < end; ++i) below += children_of(tree.nodes[i]);
    begin = end;
    end += below;
  }
  return {begin, end};
}

// The chart row of node `index` (breadth-first layout).
int level_of(const Tree& tree, int rows, std::uint32_t index) {
  std::uint32_t begin = 0, end = 1;
  int level = rows - 1;
  while (index >= end) {
    std::uint32_t below = 0;
    for (std::uint32_t i = begin; i < end; ++i) below += children_of(tree.nodes[i]);
    begin = end;
    end += below;
    --level;
  }
  return level;
}

struct Place {
  std::size_t tree = 0;
  std::uint32_t node = 0;
};

// The k-th node (0-based, in tree then index order) for which want(tree, index) holds.
template <typename Want>
Place kth(const Forest& f, std::size_t k, Want&& want) {
  for (std::size_t t = 0; t < f.trees.size(); ++t) {
    const auto& nodes = f.trees[t].nodes;
    for (std::uint32_t i = 0; i < nodes.size(); ++i) {
      if (want(t, i) && k-- == 0) return {t, i};
    }
  }
  return {};
}

template <typename Want>
std::size_t count(const Forest& f, Want&& want) {
  std::size_t n = 0;
  for (std::size_t t = 0; t < f.trees.size(); ++t) {
    for (std::uint32_t i = 0; i < f.trees[t].nodes.size(); ++i) n += want(t, i) ? 1 : 0;
  }
  return n;
}

// A random stitch (not a cast-on leaf) of the forest; a well-formed forest always has one.
Place random_stitch(const Forest& f, std::mt19937_64& rng) {
  auto stitch = [&](std::size_t t, std::uint32_t i) { return !f.trees[t].nodes[i].cast_on; };
  return kth(f, pick(count(f, stitch), rng), stitch);
}

// `dst` with its subtree at `at` replaced by the subtree of `src` at `from`, laid out breadth
// first (children contiguous, after their parent). src may be dst itself.
Tree splice(const Tree& dst, std::uint32_t at, const Tree& src, std::uint32_t from) {
  struct Item {
    const Tree* tree;
    std::uint32_t index;
    bool from_src;
  };
  std::vector<Item> queue;  // queue[k] becomes out.nodes[k]
  queue.reserve(dst.nodes.size() + src.nodes.size());
  queue.push_back({&dst, 0, false});
  Tree out;
  out.nodes.reserve(dst.nodes.size() + src.nodes.size());
  for (std::size_t k = 0; k < queue.size(); ++k) {
    Item item = queue[k];
    if (!item.from_src && item.index == at) item = {&src, from, true};
    Node node = item.tree->nodes[item.index];
    const int n = children_of(node);
    const std::uint32_t first = node.first_child;
    node.first_child = n == 0 ? 0u : static_cast<std::uint32_t>(queue.size());
    out.nodes.push_back(node);
    for (int c = 0; c < n; ++c) queue.push_back({item.tree, first + c, item.from_src});
  }
  return out;
}

bool has_cast_on(const Tree& tree) {
  for (const Node& n : tree.nodes) {
    if (n.cast_on) return true;
  }
  return false;
}

// Puts `fresh` in place of tree t unless the forest would then stand on no cast-on stitch
// (every path ending in a yarn-over), which is not a well-formed forest.
bool replace_tree(Forest& f, std::size_t t, Tree&& fresh) {
  bool grounded = has_cast_on(fresh);
  for (std::size_t u = 0; u < f.trees.size() && !grounded; ++u) {
    grounded = u != t && has_cast_on(f.trees[u]);
  }
  if (!grounded) return false;
  f.trees[t] = std::move(fresh);
  return true;
}

}  // namespace

bool crossover(Forest& a, const Forest& b, std::mt19937_64& rng) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges(b.trees.size());
  // A few tries: b may have no stitch at the chosen row (its trees may end in yarn-overs).
  for (int attempt = 0; attempt < 4; ++attempt) {
    const Place p = random_stitch(a, rng);
    const int row = level_of(a.trees[p.tree], a.rows, p.node);
    std::size_t candidates = 0;
    for (std::size_t t = 0; t < b.trees.size(); ++t) {
      ranges[t] = level_range(b.trees[t], b.rows, row);
      candidates += ranges[t].second - ranges[t].first;
    }
    if (candidates == 0) continue;
    std::size_t k = pick(candidates, rng);
    std::size_t t = 0;
    for (std::size_t size; k >= (size = ranges[t].second - ranges[t].first); ++t) k -= size;
    const std::uint32_t from = ranges[t].first + static_cast<std::uint32_t>(k);
    return replace_tree(a, p.tree, splice(a.trees[p.tree], p.node, b.trees[t], from));
  }
  return false;
}

bool subtree_mutation(Forest& f, std::mt19937_64& rng) {
  const Place p = random_stitch(f, rng);
  const Tree fresh = random_tree(level_of(f.trees[p.tree], f.rows, p.node), rng);
  return replace_tree(f, p.tree, splice(f.trees[p.tree], p.node, fresh, 0));
}

bool flip_slant(Forest& f, std::mt19937_64& rng) {
  auto slanted = [&](std::size_t t, std::uint32_t i) {
    const Node& n = f.trees[t].nodes[i];
    return !n.cast_on && (n.symbol == Symbol::k2tog || n.symbol == Symbol::ssk);
  };
  const std::size_t n = count(f, slanted);
  if (n == 0) return false;
  const Place p = kth(f, pick(n, rng), slanted);
  Node& node = f.trees[p.tree].nodes[p.node];
  node.symbol = node.symbol == Symbol::k2tog ? Symbol::ssk : Symbol::k2tog;
  return true;
}

bool lengthen_plain_run(Forest& f, std::mt19937_64& rng) {
  auto on_decrease = [&](std::size_t t, std::uint32_t i) {
    const auto& nodes = f.trees[t].nodes;
    const Node& n = nodes[i];
    if (n.cast_on || n.symbol != Symbol::k) return false;
    const Node& below = nodes[n.first_child];
    return !below.cast_on && is_decrease(below.symbol);
  };
  const std::size_t n = count(f, on_decrease);
  if (n == 0) return false;
  const Place p = kth(f, pick(n, rng), on_decrease);
  Tree& tree = f.trees[p.tree];
  const std::uint32_t dec = tree.nodes[p.node].first_child;
  const Node& decrease = tree.nodes[dec];
  const std::uint32_t kept =
      decrease.first_child + static_cast<std::uint32_t>(pick(consumes(decrease.symbol), rng));
  // The replacement: a k (index 0) over the kept child's subtree (index 1 onwards).
  Tree plain;
  plain.nodes.push_back(Node{false, Symbol::k, 1});
  const Tree kept_subtree = splice(tree, 0, tree, kept);  // the subtree at `kept`, alone
  plain.nodes.insert(plain.nodes.end(), kept_subtree.nodes.begin(), kept_subtree.nodes.end());
  for (std::size_t i = 1; i < plain.nodes.size(); ++i) {
    if (children_of(plain.nodes[i]) > 0) ++plain.nodes[i].first_child;
  }
  return replace_tree(f, p.tree, splice(tree, dec, plain, 0));
}

bool shorten_plain_run(Forest& f, std::mt19937_64& rng) {
  auto on_plain = [&](std::size_t t, std::uint32_t i) {
    const auto& nodes = f.trees[t].nodes;
    const Node& n = nodes[i];
    if (n.cast_on || n.symbol != Symbol::k) return false;
    const Node& below = nodes[n.first_child];
    return !below.cast_on && below.symbol == Symbol::k;
  };
  const std::size_t n = count(f, on_plain);
  if (n == 0) return false;
  const Place p = kth(f, pick(n, rng), on_plain);
  const Tree& tree = f.trees[p.tree];
  const std::uint32_t lower = tree.nodes[p.node].first_child;
  const int row = level_of(tree, f.rows, lower);
  // The decrease over two cast-on placeholders; then the old subtree goes in on one side, a
  // new tree (or, below row 0, a cast-on stitch) on the other. A breadth-first tree has the
  // root's children at 1 and 2.
  Tree dec;
  dec.nodes = {Node{false, pick(2, rng) == 0 ? Symbol::k2tog : Symbol::ssk, 1}, Node{true, Symbol::k, 0},
               Node{true, Symbol::k, 0}};
  const std::uint32_t kept = 1 + static_cast<std::uint32_t>(pick(2, rng));
  dec = splice(dec, kept, tree, tree.nodes[lower].first_child);
  if (row > 0) dec = splice(dec, kept == 1 ? 2 : 1, random_tree(row - 1, rng), 0);
  return replace_tree(f, p.tree, splice(tree, lower, dec, 0));
}

Symbol mirrored_symbol(Symbol s) {
  if (s == Symbol::k2tog) return Symbol::ssk;
  if (s == Symbol::ssk) return Symbol::k2tog;
  return s;
}

bool point_mutation(Forest& f, std::mt19937_64& rng) {
  auto others = [](Symbol s) {
    std::vector<Symbol> out;
    for (Symbol o : kAllSymbols) {
      if (o != s && consumes(o) == consumes(s)) out.push_back(o);
    }
    return out;
  };
  auto has_other = [&](std::size_t t, std::uint32_t i) {
    const Node& node = f.trees[t].nodes[i];
    return !node.cast_on && !others(node.symbol).empty();
  };
  const std::size_t n = count(f, has_other);
  if (n == 0) return false;
  const Place p = kth(f, pick(n, rng), has_other);
  Node& node = f.trees[p.tree].nodes[p.node];
  const std::vector<Symbol> choices = others(node.symbol);
  node.symbol = choices[pick(choices.size(), rng)];
  return true;
}

namespace {

// The mirror image of a tree, laid out breadth first.
Tree mirror_of(const Tree& src) {
  Tree out;
  out.nodes.reserve(src.nodes.size());
  std::vector<std::uint32_t> queue{0};  // queue[k]: the src node that becomes out.nodes[k]
  queue.reserve(src.nodes.size());
  for (std::size_t k = 0; k < queue.size(); ++k) {
    Node node = src.nodes[queue[k]];
    const int n = children_of(node);
    const std::uint32_t first = node.first_child;
    node.symbol = mirrored_symbol(node.symbol);
    node.first_child = n == 0 ? 0u : static_cast<std::uint32_t>(queue.size());
    out.nodes.push_back(node);
    for (int c = n - 1; c >= 0; --c) queue.push_back(first + static_cast<std::uint32_t>(c));
  }
  return out;
}

}  // namespace

bool mirror_tree(Forest& f, std::mt19937_64& rng) {
  const std::size_t n = f.trees.size();
  if (n < 2) return false;
  if (pick(2, rng) == 0) {
    // The whole of one half over the other: every row becomes mirror-symmetric.
    const bool right_to_left = pick(2, rng) == 0;
    Forest out = f;
    for (std::size_t t = 0; t < n / 2; ++t) {
      const std::size_t from = right_to_left ? t : n - 1 - t, to = n - 1 - from;
      out.trees[to] = mirror_of(f.trees[from]);
    }
    for (const Tree& tree : out.trees) {
      if (has_cast_on(tree)) {
        f = std::move(out);
        return true;
      }
    }
    return false;
  }
  std::size_t t = pick(n, rng);
  if (t == n - 1 - t) t = (t + 1) % n;  // the middle tree of an odd width: a neighbour instead
  return replace_tree(f, t, mirror_of(f.trees[n - 1 - t]));
}

bool swap_trees(Forest& f, std::mt19937_64& rng) {
  if (f.trees.size() < 2) return false;
  const std::size_t i = pick(f.trees.size(), rng);
  std::size_t j = pick(f.trees.size() - 1, rng);
  if (j >= i) ++j;
  std::swap(f.trees[i], f.trees[j]);
  return true;
}

void decode_into(const Forest& forest, Chart& chart) {
  chart.rows.resize(forest.rows);
  for (Row& row : chart.rows) row.clear();
  for (const Tree& tree : forest.trees) {
    // Breadth first layout: each level is a contiguous run of nodes, in knitting order, and the
    // next level is as long as the stitches this level is worked over.
    std::size_t begin = 0, end = 1;
    for (int row = forest.rows - 1; row >= 0 && begin < end; --row) {
      std::size_t below = 0;
      Row& out = chart.rows[row];
      for (std::size_t i = begin; i < end; ++i) {
        const Symbol s = tree.nodes[i].symbol;
        out.push_back(s);
        below += kConsumes[static_cast<int>(s)];
      }
      begin = end;
      end += below;
    }
  }
}

}  // namespace atelier::lace
