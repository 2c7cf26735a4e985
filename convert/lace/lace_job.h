// The `lace` conversion (issue 7): a job file of parameters -> a lace chart evolved by genetic
// programming (algorithms/lace/evolve.h, Ekart 2007), or variations of a start chart, and
// everything a hand knitter or a machine needs.
//
// Input: the job file (its parameters are already merged into the request, see convert.h) or
// "-". Parameters: lace_params.h. Writes into the output folder, each file atomically:
//   chart.json        {"rows": [[symbol, ...], ...], "cast_on", "repeats_wide",
//                     "repeats_high"}: row 0 the first knitted, each row right to left as a
//                     knitter reads it, purl rows omitted (lace_chart_json.h)
//   chart.svg         the chart with the standard symbols and a legend (lace_chart.h)
//   chart.pdf         the same, printable (A4)
//   instructions.txt  written row-by-row instructions (algorithms/lace/instructions.h); they
//                     parse back into the chart
//   lace.k            knitout for a V-bed machine: lace by transfers with racking
//   preview.png       the fabric, repeats_wide x repeats_high repeats (algorithms/lace/preview.h)
//                     at most 50000 stitches (fewer repeats, down to one) and 4096 px a
//                     side (smaller stitches, then fewer repeats); report.json "preview" says
//                     what is drawn
//   report.json       fitness terms and weights, constraint check, stitch counts, generations
//                     and the best score per generation, what the lace carriage of a Brother
//                     machine (AYAB) can and cannot do with the chart and why (the first 100
//                     problems and problems_total), params, timings
// Limits beyond the parameters' ranges (a ParamError naming the key): population x width x
// rows <= 2e7 (memory), x generations <= 4e9, population^2 x generations <= 2e10 (time), and
// the swatch (width x repeats_wide) x (rows x repeats_high) <= 500000 stitches. A start chart
// must be worked over 2..200 stitches, have at most 200 rows and end as wide as it starts.
// Thread-safe per request (no shared state).
#pragma once

#include "convert/convert.h"

namespace atelier {

// The file the lace carriage is fed (rows of symbols, lace_chart_json.h).
inline constexpr const char* kLaceChartFile = "chart.json";

// Throws ParamError (parameters, an unreadable start chart) and ConvertError (outputs).
ConvertResult convert_lace(const ConvertRequest& request);

}  // namespace atelier
