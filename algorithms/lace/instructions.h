// Written lace instructions (issue 7, section 2): a chart as a knitter reads it in a pattern
// book, "Row 1 (RS): k2, yo, ssk, k3, [yo, k2tog] 2 times, k1. (12 sts)", and the reader that
// takes exactly that text back to the chart.
//
// Format (write_instructions produces it, parse_instructions reads it):
//   Lace pattern: <title>                    (or "Lace pattern" when the title is empty;
//                                            line breaks in the title become spaces)
//   Multiple of N stitches; 2R-row repeat (R right-side rows charted).
//   Cast on a multiple of N stitches.
//   <blank>
//   Row 1 (RS): <items>. (W sts)             one line per chart row r: "Row 2r+1 (RS)"
//   Row 2 and all WS rows: purl.             (after row 1; when RS rows have a double yarn-over:
//                                            "..., except: purl 1, knit 1 into each double
//                                            yarn-over (yo twice) of the row below (rows 2 and 6).")
//   Row 3 (RS): ...
//   Repeat rows 1-2R.                        (or, when the last row is not as wide as the
//                                            cast-on, "Work rows 1-2R once (...)")
//   <blank>
//   Abbreviations: ...                       (the rest of that paragraph is skipped on reading)
// Items are in knitting order (Chart::rows[r][0] first), separated by ", ": "kN" for a run of N
// plain stitches, the symbol names yo, k2tog, ssk, sk2p, s2kp, and "[item, item, ...] N times" for a
// group of >= 2 items repeated N >= 2 times consecutively (never nested). Among all such
// writings of a row the shortest text is chosen. "(W sts)" is the stitches the row makes.
// Widths in stitches. Pure functions, thread-safe.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "algorithms/lace/chart.h"

namespace atelier::lace {

struct InstructionsInfo {
  std::string title;  // e.g. the job's name; may be empty
};

// The instructions for a chart worked over `cast_on` stitches (its repeat width). Throws
// std::invalid_argument with knittable()'s reason when the chart cannot be knitted from cast_on.
std::string write_instructions(const Chart& chart, int cast_on, const InstructionsInfo& info);

// One row's items as written after "Row N (RS): " (no final full stop), e.g.
// "k2, yo, ssk, k3, [yo, k2tog] 2 times, k1". An empty row gives "".
std::string write_row(const Row& row);

struct ParsedInstructions {
  Chart chart;
  int cast_on = 0;
};

// Reads write_instructions' format back. Header, "Row 2 and all WS rows", "Repeat/Work rows" and
// abbreviation lines are recognised and skipped, blank lines ignored, "Row N (RS):" matched
// case-insensitively; rows must be consecutive odd numbers from 1. A "(W sts)" count, when
// present, must equal the stitches the row makes. cast_on comes from "Cast on a multiple of N",
// else "Multiple of N", else what row 1 is worked over; the chart must be knittable from it.
// Throws std::invalid_argument "line N: <problem>" (1-based line of the text). Text from
// outside is bounded before anything is built from it: a line longer than kMaxLineChars
// (std::regex recurses per character), a row making more than kMaxRowStitches or a chart of
// more than kMaxChartStitches stitches ("k99999999" would ask for gigabytes) is refused.
inline constexpr std::size_t kMaxLineChars = 20000;
inline constexpr std::size_t kMaxRowStitches = 10000;
inline constexpr std::size_t kMaxChartStitches = 1000000;
ParsedInstructions parse_instructions(std::string_view text);

}  // namespace atelier::lace
