// Knitout (knitout-2) for a two-colour Fair-Isle pattern.
//
// Needle mapping: stitch column c of the pattern (0 = leftmost stitch as seen on the right
// side of the fabric) is front-bed needle f(c+1); knitout numbers needles left to right as
// seen from the front of the machine, which is how the knitout visualiser shows the face.
// Pattern row 1 is knitted first: the bottom row of the picture (grid row rows-1), so the
// fabric, cast-on edge down, is the picture upright; with first_row_top the top row (grid
// row 0: knitted top-down, the fabric comes off upside down).
//
// Each pattern row is two passes in the same direction: carrier 1 (background yarn) knits the
// needles of background stitches (0), then carrier 2 (contrast yarn) the contrast stitches
// (1); the idle yarn floats behind. No `miss`: a carrier goes from stitch to stitch by itself
// and turns at its last stitch of a row (knitout_longest_float() measures what that leaves,
// which report.json's longest_float states). Carrier 2 comes in (inhook) just before its first
// stitch, so the hook never blocks carrier 1's needles. The direction alternates per row.
// Headers: knitout_header.h's; the rest are plain comments.
// After the last row carrier 2 leaves and carrier 1 binds off (the chain bind-off of knitout
// examples: knit, move the loop onto the next needle, knit the two), ending in a short tail
// knitted on the last needle, which is then dropped.
// Every pattern row is preceded by a comment "; row N" so tools can follow the file.
//
// Pure; thread-safe.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace atelier {

struct KnitoutOptions {
  double stitches_per_10cm = 28;  // written as ;;Gauge: in needles per inch
  std::string title;              // a comment line naming the source
  bool first_row_top = false;     // [knit] first_row = "top": grid row 0 is knitted first
  // Non-empty: why the pattern cannot be knitted as is, written as the first comment line
  // ("; NOT KNITTABLE AS IS: ...").
  std::string not_knittable;
  // Comment lines after it ("; NOTE: ..."): what else the user must know before knitting
  // (floats longer than max_float at free row edges or in a relaxed area).
  std::vector<std::string> notes;
};

// The longest float make_knitout(grid) holds: for each carrier, the needles its yarn runs
// behind between two of its stitches in knitting order (the run of the other colour inside a
// row, and at a row's end the way from its last stitch to its first of the next row it knits;
// carrier 1 from the plain rows to row 1 and from the last row to the bind-off). A yarn is not
// carried into a row-edge run of the other colour, so with anchoring free edge runs are floats
// only as far as a turn spans them.
int knitout_longest_float(const cv::Mat& grid, bool first_row_top);

// `grid`: CV_8UC1, 1 = contrast, 0 = background; row 0 = top of the picture.
std::string make_knitout(const cv::Mat& grid, const KnitoutOptions& options);

}  // namespace atelier
