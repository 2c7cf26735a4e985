// Knitout (knitout-2) for a lace chart on a V-bed machine: lace.k of a lace job.
//
// Layout: one carrier (1); every stitch lives on the front bed. Knitting-order stitch o of a
// row (right-side right first) is needle f(R - o), R = the right edge, fixed for the whole
// piece, so f1 is the leftmost needle seen on the right side (as in pattern.k of the knit
// kind) and rows that widen or narrow grow and shrink on the left.
// Sequence: a tuck cast-on over the chart's first width (cast_on x repeats_wide), two plain
// rows, then the chart rows x repeats_high with each row tiled repeats_wide times side by
// side. Every chart row is preceded by "; row N" (N counts chart rows from 1, repeats
// included) and is: transfers, then the right-side row (knitted leftwards, "-"), then the
// wrong-side row (knitted rightwards on the front bed too, so the fabric is stockinette).
// Lace by transfers with racking: the stitches that move or join a decrease go to the back bed
// at rack 0, then return to the front one stack layer at a time (every bottom stitch, then the
// ones on them), each by "rack d" + "xfer bN f(N+d)" with |d| <= 4, in several hops over
// empty needles when it has further to go; the rack returns to 0 before knitting. A
// yarn-over is a needle left empty, which the next knit pass casts a loop onto. No loop is
// dropped: the work stays on the needles at the end for binding off or waste yarn, as the knit
// kind's pattern.k does.
//
// Pure; thread-safe.
#pragma once

#include <string>

#include "algorithms/lace/chart.h"

namespace atelier {

struct LaceKnitoutOptions {
  std::string title;              // a comment line naming the source
  int repeats_wide = 3, repeats_high = 3;
  double stitches_per_10cm = 28;  // written as ;;Gauge: in needles per inch
};

// Throws std::invalid_argument when the chart cannot be knitted from cast_on stitches, a
// repeat count is < 1, or repeats_high > 1 for a chart whose last row is not cast_on wide.
std::string make_lace_knitout(const lace::Chart& chart, int cast_on, const LaceKnitoutOptions& options);

}  // namespace atelier
