// Evaluation of a lace chart (Ekart 2007, sections 4 and 6): the paper's constraints as
// violation counts, and the aesthetic objectives combined by eq. 2 into one score. Used by the
// genetic programming (evolve.h) and by the converter for report.json.
// Pure functions on value types, thread-safe.
#pragma once

#include "algorithms/lace/chart.h"

namespace atelier::lace {

// Weights of eq. 2. Each must be >= 0 and finite. Eq. 2 maximises the weighted sum of the
// first group (the paper's holes and knit_length, its tree depth, and the discussion's
// symmetry and connectedness of holes) minus the weighted sum of the second group, the terms to
// minimise: how far the yarn-over share is outside [yo_share_min, yo_share_max] (classic lace
// keeps about 10-25 % holes framed by plain knitting; `holes` alone drives a chart to a 40 %
// random mesh) and how far the rows' widths wander from the cast-on (section 7: "a limitation
// on how much variation in size is allowed").
struct Weights {
  double holes = 1.0, knit_length = 0.5, depth = 0.2, symmetry = 1.0;
  double hole_lines = 3.0;     // holes in lines (hole_lines.h)
  double yo_band = 50.0;       // minimised: yo_band_distance
  double width_change = 0.5;   // minimised: width_change
  // The yarn-over share band, 0 <= yo_share_min <= yo_share_max <= 1 (fractions of cells).
  double yo_share_min = 0.10, yo_share_max = 0.25;
};

// Constraint violations, in stitches or cells; all zero <=> the chart satisfies the paper's
// constraints (and any extra ones of the caller).
struct Constraints {
  // |cast_on - consumed(row 0)| + |cast_on - produced(last row)|: zero exactly when the chart is
  // worked over the cast-on and ends as wide as it (eq. 1, |yo| = |k2tog| + |ssk| + 2|sk2p|).
  int balance_error = 0;
  // Sum over rows of max(0, run - 2) over the runs of yarn-overs of the row taken as repeated
  // side by side (a run may wrap from the row's end to its start, as in
  // max_adjacent_yarn_overs(row, true)). A row of nothing but yarn-overs counts its length.
  int adjacent_yo_excess = 0;
  // Sum over rows of max(0, |produced(row) - cast_on| - tol) + max(0, |produced(row) -
  // produced(row 0)| - tol): intermediate rows stay within the tolerance of the cast-on and of
  // the first row (width_ok()'s reference), so a feasible chart passes width_ok(chart, tol).
  int width_excess = 0;
  // Violations of the caller's own constraints (EvolveParams::extra_violations), e.g. rows the
  // knitting machine's lace carriage cannot do. evaluate() leaves it 0.
  int extra = 0;

  int total() const { return balance_error + adjacent_yo_excess + width_excess + extra; }
  bool ok() const { return total() == 0; }
};

// The aesthetic measurements, each in [0, 1] (1 best).
struct Objectives {
  // Holes (paper: number of yarn-overs, maximised): min(1, 1.5 * |yo| / cells). 2/3 of the
  // cells is the most yarn-overs a balanced chart can hold with at most two side by side
  // ("yo, sk2p, yo" repeated), so such a chart reaches 1. An all-plain chart has 0.
  double holes = 0;
  // Knit length (paper: "the length of plain stitches knit on top of each other"): the mean
  // length, in rows, of the vertical runs of plain stitches (a k worked over a k continues the
  // run) divided by the chart's rows. |k| / (|k| - |k worked over a k|) / rows. An all-plain
  // chart has 1 (every column one run through all rows); a chart without k has 0.
  double knit_length = 0;
  // Depth (the paper's tree-depth objective; our trees are full depth by construction): how far
  // down the lace reaches in each tree, i.e. the mean over the last row's stitches (the trees)
  // of (row distance from the root to the deepest non-plain stitch of the tree + 1) / rows,
  // 0 for an all-plain tree. A chart whose every tree has a non-plain stitch in row 0 has 1.
  double depth = 0;
  // Symmetry: mirror symmetry about the chart's vertical centre line, each row mirrored about
  // its own centre (so rows of different widths are compared centred), k2tog mirroring to ssk
  // and the others to themselves: of the motif's cells (those where the cell or its mirror
  // image is not a plain stitch), the fraction equal to their mirror image's symbol; 0 for a
  // chart without lace (plain knitting is trivially symmetric and must not win on it).
  double symmetry = 0;
  // Connectedness of the holes (hole_lines.h, HoleLines::hole_lines): the share of yarn-overs
  // that are part of a line of holes over at least 3 consecutive rows; 0 without holes.
  double hole_lines = 0;
  // The yarn-over share, |yo| / cells (not an objective itself: yo_band_distance is).
  double yo_share = 0;
  // Minimised: max(0, yo_share_min - yo_share) + max(0, yo_share - yo_share_max), 0..1.
  double yo_band_distance = 0;
  // Minimised: the mean over rows of |produced(row) - cast_on| / cast_on, capped at 1.
  double width_change = 0;
};

struct Evaluation {
  Constraints constraints;
  Objectives objectives;
  // Eq. 2: w.holes * holes + w.knit_length * knit_length + w.depth * depth + w.symmetry *
  // symmetry + w.hole_lines * hole_lines - w.yo_band * yo_band_distance -
  // w.width_change * width_change, minus penalty(constraints, w). Higher is better.
  double score = 0;
};

// The weighted sum of eq. 2 (in [-(yo_band + width_change), sum of the maximised weights]).
double weighted_sum(const Objectives& o, const Weights& w);

// 0 for a feasible chart, else (sum of the seven weights + 1) * (1 + constraints.total()), so any chart
// that violates a constraint scores below every feasible chart, and fewer violations score
// higher among equal objectives.
double penalty(const Constraints& c, const Weights& w);

// weighted_sum(o, w) - penalty(c, w).
double score(const Constraints& c, const Objectives& o, const Weights& w);

// Evaluates a chart meant to be worked over `cast_on` stitches (its repeat width) with
// intermediate rows allowed to differ from it by `width_tolerance` stitches. The rows must
// follow on from each other (row r consumes what row r-1 produces); row 0 may be worked over a
// different number of stitches than cast_on (that is a balance_error). Throws
// std::invalid_argument for a chart with no rows, an empty row, cast_on < 1,
// width_tolerance < 0, or rows that do not follow on.
Evaluation evaluate(const Chart& chart, int cast_on, const Weights& w, int width_tolerance);

}  // namespace atelier::lace
