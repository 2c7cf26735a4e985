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
// needles of background stitches (0) and misses the others, then carrier 2 (contrast yarn)
// knits the contrast stitches (1) and misses the rest, so the idle yarn floats behind. Both
// passes cover the whole width (a carrier with no stitch in a row just misses across), so
// both carriers always end on the same side and the direction alternates per row. This
// anchors both yarns at the edges, as machines need, whatever the solver's `anchoring` was.
// Every pattern row is preceded by a comment "; row N" so tools can follow the file.
//
// Pure; thread-safe.
#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace atelier {

struct KnitoutOptions {
  double stitches_per_10cm = 28;  // written as ;;Gauge: in needles per inch
  std::string title;              // a comment line naming the source
  bool first_row_top = false;     // [knit] first_row = "top": grid row 0 is knitted first
};

// `grid`: CV_8UC1, 1 = contrast, 0 = background; row 0 = top of the picture.
std::string make_knitout(const cv::Mat& grid, const KnitoutOptions& options);

}  // namespace atelier
