// The genetic operators on forests (Ekart 2007, section 5 and the specialised mutations of
// section 8), and a fast decode for the forests they build.
//
// Every operator takes a well-formed full-depth forest (forest_error() == "") laid out breadth
// first (each level's nodes contiguous and in order, as encode(), random_forest() and these
// operators write them) and leaves it so, with the same rows and the same number of trees; what changes is the stitches
// (so the cast-on, i.e. eq. 1's balance, may change). Each returns whether it changed
// anything: false means no place to apply it was found (or the change would have left no
// path down to the cast-on, i.e. no cast-on stitch at all), and the forest is untouched.
// Random choices use the caller's generator (one thread at a time). Rows are chart rows
// (0-based, rows[0] first knitted); a node's row is its level in the tree.
#pragma once

#include <random>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/stitch_tree.h"

namespace atelier::lace {

// Subtree crossover (Koza): a random stitch of `a` (uniform over all stitches, cast-on leaves
// excluded) is replaced by a copy of a random subtree of `b` rooted at the same chart row, so
// depth stays full. a.rows must equal b.rows.
bool crossover(Forest& a, const Forest& b, std::mt19937_64& rng);

// Subtree mutation: a random stitch is replaced by a new random tree rooted at its row
// (random_tree()).
bool subtree_mutation(Forest& f, std::mt19937_64& rng);

// Flip a slant (the paper's proposed "\" -> "/"): one random k2tog becomes ssk or ssk becomes
// k2tog. False when the forest has no single decrease.
bool flip_slant(Forest& f, std::mt19937_64& rng);

// Lengthen a run of plain stitches (the paper's "increasing the length of plain stitches knit
// on top of each other"): below a random plain stitch whose one child is a decrease, that
// decrease becomes a k worked over one (random) of the decrease's own children; the other
// children's subtrees go. The run of k above it grows by one row and the tree stays full
// depth. False when no k stands on a decrease.
bool lengthen_plain_run(Forest& f, std::mt19937_64& rng);

// Shorten a run of plain stitches (the paper's "decreasing the length of plain stitches knit on
// top of each other"), the inverse of lengthen_plain_run(): below a random plain stitch whose
// one child is also plain, that child becomes a k2tog or ssk (even odds) worked over its old
// child's subtree and a new random tree (random_tree(); a cast-on stitch below row 0) on a
// random side. The run above is cut by one row. False when no k stands on a k.
bool shorten_plain_run(Forest& f, std::mt19937_64& rng);

// Point mutation (Koza; the paper's section 8): a random stitch whose symbol shares its number
// of stitches worked over with another symbol (kAllSymbols, consumes()) gets one of those
// others, its children untouched. The chart keeps every row's widths, so a feasible chart
// stays feasible. False when no stitch has such a symbol.
bool point_mutation(Forest& f, std::mt19937_64& rng);

// Mirror symmetry (the paper's discussion): with even odds, either tree t is replaced by the
// mirror image of tree n-1-t (children in reverse order, k2tog <-> ssk, mirrored_symbol()) for
// a random t, or every tree of one half (random) by the mirror image of its partner in the
// other half. A chart whose trees are all so paired has every row mirror-symmetric. False with
// < 2 trees or when the copy would leave the forest on no cast-on stitch.
bool mirror_tree(Forest& f, std::mt19937_64& rng);

// The symbol seen in a mirror: k2tog <-> ssk, the others themselves.
Symbol mirrored_symbol(Symbol s);

// The paper's order change (section 3): two random trees change places. False with < 2 trees.
bool swap_trees(Forest& f, std::mt19937_64& rng);

// decode(forest) without the checks, into `chart` (its rows' storage is reused). Only for
// well-formed forests laid out breadth first, each level's nodes contiguous and in order, as
// encode(), random_tree(), random_forest() and these operators write them; anything else is
// undefined behaviour.
void decode_into(const Forest& forest, Chart& chart);

}  // namespace atelier::lace
