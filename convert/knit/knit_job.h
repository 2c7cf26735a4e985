// The `knit` conversion: image -> stitch grid -> dithered start -> float solver -> outputs.
//
// Writes into request.output_dir: pattern.png (1 px per stitch, black = contrast),
// preview.png (stitch-shaped render in the configured yarn colours), chart.pdf (see
// knit_chart.h), pattern.k (see knit_knitout.h) and report.json (parameters, metrics, timings).
// Not thread-safe per request; separate requests may run concurrently.
#pragma once

#include "convert/convert.h"

namespace atelier {

// The file a knitting machine is fed (1 pixel per stitch, black = contrast).
inline constexpr const char* kKnitPatternFile = "pattern.png";

// Throws ConvertError (input, relax mask, output files) and ParamError (parameters).
ConvertResult convert_knit(const ConvertRequest& request);

}  // namespace atelier
