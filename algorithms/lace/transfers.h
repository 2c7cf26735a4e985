// Where each stitch of a chart row goes, and how a Brother lace carriage gets it there.
// Used by the knitout writer (V-bed, racking; free to relayout) and by the AYAB lace planner
// (single bed, lace carriage). Pure functions, value types, thread-safe.
//
// Stitch structure of one chart row (row_transfers): the row is worked over the stitches of
// the row below, s = 0, 1, ... in knitting order (chart.h). Each consumed stitch s belongs to
// the output stitch target[s] (the symbol worked over it; a symbol's stitches are contiguous)
// and lies at layer[s] of that stitch's stack, 0 = bottom:
//   k: [s]   k2tog (s, s+1): s bottom, s+1 on top (leans right on the right side)
//   ssk (s, s+1): s+1 bottom, s on top (leans left)
//   sk2p (s, s+1, s+2): s+1 bottom, s+2 on it, s on top (slip 1, k2tog, pass slipped over:
//     leans left)
//   s2kp (s, s+1, s+2): s+2 bottom, s on it, s+1 on top (slip 2 together, k1, pass the 2
//     over: the centred double decrease)
//   yo: consumes nothing (an empty needle that the next knit row casts a loop onto)
//
// Brother lace-carriage model (our decision where the machine manuals are vague):
// - The machine knits with the purl side facing the operator, so knitting-order index j
//   (right-side right first) sits on needle start + j counted from the operator's LEFT.
//   Needles are never added or taken away: every row must consume exactly what it produces.
// - Per chart row: lace-carriage (L) passes, then the knit carriage knits 2 rows (the RS row
//   and the plain WS row) over all needles: an emptied needle casts on a new loop (the
//   yarn-over's hole); a needle holding 2 or 3 loops knits them as one stitch (the decrease),
//   the loop that arrived last lying on top.
// - The L carriage is parked at the LEFT: its passes alternate left->right, right->left, ...
//   and each chart row uses an even number of passes (a blank pass pads) so it ends parked
//   left again. A selected needle's loops move one needle in the direction of travel, onto
//   whatever the neighbour holds (arriving on top). Two adjacent needles are never selected
//   in one pass. A stitch only arrives on a needle whose loops are final (they will not move
//   again), only as the next in its stack's order, and only onto an empty needle or onto its
//   own decrease. So plain stitches between a yarn-over and its decrease shift one needle
//   per pass, the one nearest the decrease first.
// - Not possible: a row that changes the width; a stacking order that cannot arrive
//   last-on-top ("yo, k2tog", also with plain stitches between: the bottom stitch would have
//   to slide under the top one); more than max_passes_per_row passes. Each problem names the
//   chart row and stitch. A transfer off the working range cannot arise: a stitch only
//   travels between its own needle and its target, both inside the row (and each repeat's
//   stitches stay inside that repeat, as every row is balanced).
#pragma once

#include <string>
#include <vector>

#include "algorithms/lace/chart.h"

namespace atelier::lace {

struct RowTransfers {
  int consumed = 0;          // stitches of the row below
  int produced = 0;          // stitches the row makes
  std::vector<int> target;   // per consumed stitch: the output stitch worked over it
  std::vector<int> layer;    // per consumed stitch: its place in that stitch's stack, 0 = bottom
  // Per output stitch: the consumed stitches it is made through, bottom first (empty for yo).
  std::vector<std::vector<int>> stack;
};

// The row's stitch structure (see above). Any row works; consumed may differ from produced.
RowTransfers row_transfers(const Row& row);

// The row repeated `times` side by side (knitting order: repeat 0 first). times >= 1.
Row tile_row(const Row& row, int times);

// The knitter's name of stored chart row r (0-based): "row 1 (RS)", "row 3 (RS)", ...
std::string rs_row_name(int r);

struct CarriageLimits {
  int max_passes_per_row = 12;  // lace-carriage passes per chart row, blank padding included
};

enum class LaceDirection { left_to_right, right_to_left };  // as the operator sees the bed

struct LacePass {
  LaceDirection direction = LaceDirection::left_to_right;
  // Selected needles as knitting-order positions (0 = the working range's leftmost needle),
  // ascending, never two adjacent.
  std::vector<int> needles;
};

struct LaceRowSchedule {
  std::vector<LacePass> passes;       // even count; empty when the row needs no transfer
  std::vector<std::string> problems;  // empty <=> the passes do the row
  bool ok() const { return problems.empty(); }
};

// The lace-carriage passes for stored chart row `chart_row` (0-based, for messages) worked
// `repeats` times side by side over the same number of needles (transfers may cross repeat
// boundaries). Problems name the row and the stitch within the chart row (1-based, counted as
// the knitter reads it, from the right), once per stitch of the chart, not per repeat.
LaceRowSchedule schedule_lace_row(const Row& row, int repeats, int chart_row,
                                  const CarriageLimits& limits = {});

// V-bed transfers of one row, grouped into few passes (the knitout writer's schedule).
// Needles: stitch s of the row below sits on front needle right - s, its output stitch o on
// right - o (knitting order runs leftwards), so a stitch moves d = s - o needles (> 0
// rightwards). At rack R, f(x) faces b(x - R). Every stitch that must move (o != s, or it must
// lie on top of others on its own needle) goes to the back; a stitch more than max_rack
// needles from its target crosses the beds in rounds (back to a free front needle up to
// max_rack nearer, then to a free back needle up to max_rack nearer), each round one pass per
// racking and direction. Then, layer by layer (bottom of each stack first), one back-to-front
// pass per racking, each taking every stitch of that racking whose lower layers are home.
// Stitches that stay on their needle at the bottom of their stack never move. Several
// variants (first racking, near stitches before or after far ones) are tried and the one with
// the fewest passes kept; consecutive passes of one racking and direction are merged. The
// loop-level result is the stack order of row_transfers. Bounded: every round homes a stitch
// or brings the far ones nearer, with a step cap; |rack| <= max_rack always.
struct VbedPass {
  bool to_back = false;  // true: f(x) -> b(x - rack); false: b(y) -> f(y + rack)
  int rack = 0;
  std::vector<int> stitches;  // consumed stitch indices moved in this pass
};
struct VbedRowSchedule {
  std::vector<VbedPass> passes;  // empty when no stitch moves
  // False when no variant can place the row (a stitch would have to pass a needle holding other
  // loops); the caller then routes it in hops instead.
  bool ok = true;
};
VbedRowSchedule schedule_vbed_row(const RowTransfers& t, int max_rack);

}  // namespace atelier::lace
