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
// both carriers always end on the same side and the direction alternates per row. So every
// run of one colour in a row is a float of the other yarn, edge runs included (anchoring =
// false only frees them for hand knitting, where the yarn turns at its last stitch; a miss is
// a float): knitout_longest_float() is that float, which report.json's longest_float states.
// Headers are the knitout spec's only: ;!knitout-2, ;;Machine: (an identifier the SWG backend
// knows), ;;Gauge: (integer needles per inch), ;;Carriers: 1 2; the rest are plain comments.
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

// The machine name and gauge both writers put in the headers.
inline constexpr const char* kKnitoutMachine = "SWG091N2";
// Needles per inch, rounded, at least 1.
int knitout_gauge(double stitches_per_10cm);

// The longest run of misses of one carrier in one pass of make_knitout(grid): the longest run
// of one colour in any grid row, edges included.
int knitout_longest_float(const cv::Mat& grid);

// `grid`: CV_8UC1, 1 = contrast, 0 = background; row 0 = top of the picture.
std::string make_knitout(const cv::Mat& grid, const KnitoutOptions& options);

}  // namespace atelier
