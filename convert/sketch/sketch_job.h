// The `sketch` conversion: an image -> edges (edge-preserving smoothing, Canny) -> straight
// strokes (contours simplified, collinear pieces merged) [+ hatching of dark regions] -> each
// drawn as a human-like pencil line (algorithms/pencil) -> outputs:
//   preview.png    the pencil drawing on paper white (image size x scale, grey)
//   lines.svg      the hand-drawn paths (drawing px in the viewBox, width_mm wide), strokes and
//                  hatching in their own groups, graphite grey #3c3c3c (a colour no laser layer
//                  has by default, so the file is never cut by mistake as a `cut` job)
//   engrave.gcode  the same paths as one engrave layer (algorithms/laser/plan.h), width_mm wide at
//                  position_mm on the bed, clipped to that rectangle as the preview is to its
//                  canvas (a line near the edge may wander past it); power by pencil grade
//                  unless power_pct is set
//   report.json    parameters, pencil, counts, lengths, engraving, timings
// Parameters: sketch_params.h. Not thread-safe per request; separate requests may run at once.
#pragma once

#include "convert/convert.h"

namespace atelier {

// The program a laser runs (the drawing engraved).
inline constexpr const char* kSketchGcodeFile = "engrave.gcode";

// Throws ConvertError (unreadable image, a pencil file that cannot be read, nothing to draw,
// an engraving outside the work area) and ParamError (parameters).
ConvertResult convert_sketch(const ConvertRequest& request);

}  // namespace atelier
