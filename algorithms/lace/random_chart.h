// Random individuals for the genetic programming (Ekart 2007, section 5 step 1: "random size,
// shape and content trees"). Two kinds:
// - grown trees: top-down, each stitch drawn with probabilities that keep the expected number of
//   stitches below a stitch at 1 (so trees neither die out nor explode on average); these rarely
//   satisfy the constraints but bring shape variety;
// - row-by-row charts that already satisfy the constraints (constant width, each yarn-over
//   paired with a decrease beside it, never three yarn-overs side by side even across the
//   repeat edge), encoded into trees, so a feasible individual exists from generation 0.
// Pure functions; the generator is the caller's (one thread at a time). Widths in stitches.
#pragma once

#include <random>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/stitch_tree.h"

namespace atelier::lace {

// A random full-depth tree whose root is a stitch of chart row `row` (0-based, >= 0): its
// paths end at yarn-overs or at cast-on leaves one level below row 0. nodes[0] is the root,
// children contiguous and after their parent (stitch_tree.h layout). A tree's widest level is
// kept small (decreases are not drawn once a level holds 6 stitches) so sizes stay bounded.
Tree random_tree(int row, std::mt19937_64& rng);

// `width` grown trees spanning `rows` rows (a well-formed forest: at least one path reaches
// the cast-on, the last tree is redrawn until one does; its cast-on varies).
// width >= 1, rows >= 1.
Forest random_forest(int width, int rows, std::mt19937_64& rng);

// A chart of `rows` rows, every row `width` stitches wide and worked over `width` (so it is
// knittable from `width`, balanced, width_ok(chart, 0)), with at most two yarn-overs side by
// side even when the row is repeated. Rows are strung from units: k; yo + k2tog, k2tog + yo,
// yo + ssk, ssk + yo; yo + s2kp + yo. With `carriage_pairings`, only the pairings a lace
// carriage can make (k2tog + yo, yo + ssk, yo + sk2p + yo: the carriage cannot put s2kp's centre
// stitch on top; see transfers.h). width >= 1, rows >= 1.
Chart random_feasible_chart(int width, int rows, std::mt19937_64& rng, bool carriage_pairings = false);

// As random_feasible_chart(), but every row mirror-symmetric (the discussion's symmetry): the
// right half (first width / 2 stitches in knitting order) is strung from the same units, the
// left half is its mirror image (k2tog <-> ssk, order reversed), an odd middle stitch is k.
// Without carriage_pairings (a mirrored "k2tog, yo" is "yo, ssk", but "yo, k2tog" mirrors to
// "ssk, yo", which a lace carriage cannot make). width >= 1, rows >= 1.
Chart random_symmetric_chart(int width, int rows, std::mt19937_64& rng);

}  // namespace atelier::lace
