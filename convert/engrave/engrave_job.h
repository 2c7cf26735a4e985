// The `engrave` conversion: a photo -> a raster engraving for a GRBL laser (LightBurn's image
// mode). Parameters: engrave_params.h. The image is made grey (alpha over white), resized with
// area averaging to the output grid (width_mm at dpi across, height / line_interval_mm down)
// and turned into power per pixel and scan lines by algorithms/laser/raster.h.
// Writes into request.output_dir, each file atomically:
//   job.gcode    the program: bed coordinates, M4, one G1 per run of equal power
//   preview.png  what will be burned: the engraving's area at the output dpi (dpi / 25.4 px per
//                mm both ways), white where nothing burns. Each run is drawn as the beam burns
//                it, a round spot of spot_mm swept from its first to its last dot (so a lone dot is
//                longer than the dot pitch: the dot gain a real burn shows), at fraction p of
//                full power as grey 200 * (1 - p) (full power black; the faintest burn still
//                clearly marks, as on wood; the laser emulator's --render uses the same
//                model), drawn finely and averaged down to the output dpi
//   report.json  dpi, line interval, dithering, power range, gamma, size, position, bounds,
//                overscan, estimated time (GRBL's planner, motion_planner.h, with the [laser]
//                motion settings), G-code lines and bytes, and the streaming rate
//                they need (lines and bytes per second of burning)
// Not thread-safe per request; separate requests may run concurrently.
#pragma once

#include <string>
#include <toml++/toml.h>

#include "convert/convert.h"

namespace atelier {

inline constexpr const char* kEngraveGcodeFile = "job.gcode";

// Throws ConvertError (unreadable image, nothing to burn, outside the work area, output files)
// and ParamError (parameters).
ConvertResult convert_engrave(const ConvertRequest& request);

}  // namespace atelier
