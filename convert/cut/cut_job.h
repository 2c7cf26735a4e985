// The `cut` conversion: SVG drawing -> laser layers by stroke colour -> G-code for GRBL.
//
// Parameters (strict): `laser` = the [laser] table (see laser_params.h; the daemon injects
// its config section here; absent = defaults). Nothing else.
//
// Each stroked shape goes to the layer configured for its stroke colour (like LightBurn's
// colour layers); shapes without a stroke are not burned and counted as ignored_unstroked.
// Writes into request.output_dir, each file atomically (temporary name, then rename):
//   job.gcode    the program (algorithms/laser/plan.h), bed coordinates
//   preview.png  the work area around the job (5 mm margin) at 10 px/mm (less for very
//                large jobs, see report preview_px_per_mm), each layer's paths in its colour;
//                white is inside the work area, grey outside; travel is not drawn
//   report.json  layers, lengths, time estimate, bounds, machine, ignored shapes
// Not thread-safe per request; separate requests may run concurrently.
#pragma once

#include <string>
#include <toml++/toml.h>

#include "convert/convert.h"
#include "convert/common/laser_params.h"

namespace atelier {

// The program a laser runs.
inline constexpr const char* kCutGcodeFile = "job.gcode";

struct CutParams {
  LaserParams laser;
};

// Throws ParamError naming file, line and key.
CutParams read_cut_params(const toml::table& params, const std::string& source);

// Throws ConvertError (unreadable or malformed SVG, a stroke colour without a layer, nothing
// to burn, a job outside the work area, output files) and ParamError (parameters).
ConvertResult convert_cut(const ConvertRequest& request);

}  // namespace atelier
