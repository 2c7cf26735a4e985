// The `parquetry` conversion (issue 5): a photo + the workshop's veneer scans -> a plan of
// wood pieces (algorithms/parquetry), their cut files and one laser program.
//
// Parameters: see parquetry_params.h. With `stock` set, the whole conversion holds the
// StockLock of that folder (stock_store.h): load the stock, plan on the wood still free,
// write every output, and only then record the new pieces (so a failed conversion uses no
// wood, and two conversions never plan the same wood). The stock label of a target is its
// output folder's name (the job id in the daemon). A job converted again takes new wood and
// its earlier pieces stay taken: they may have been cut. request.together adds more targets
// planned in the same priority queue (paper 4.2), each with its own outputs and stock label.
//
// Writes into each target's output folder, each file atomically (output_files.h):
//   plan.json        result size, grid, refine, parameters; per piece id, wood, rotation_deg,
//                    source (sheet mm) and target (result mm) polygons, cost, level; per
//                    sheet used its size, pieces and placement on the laser bed
//   cuts-<wood>.svg  one per sheet used, face down (mirrored; see parquetry_svg.h)
//   assembly.svg     the pieces in place, seen from the face
//   cuts.gcode       every used sheet in turn (sorted by id): engrave its IDs (the #0000ff
//                    layer), cut its pieces (the #ff0000 layer, kerf_mm = the parquetry
//                    kerf_mm so pieces keep their size), the sheet face down with its mirrored
//                    frame (= its cut file) at the laser's design origin, the bed's rear-left
//                    corner (laser/plan.h), kerf_mm + 0.05 mm off the edges so the kerf offset
//                    of an edge piece stays in the work area: the scan's top-right corner lies
//                    in the bed's rear-left corner; between sheets a program
//                    pause (M0) after "; sheet <id>: place it face down at the origin, then
//                    resume" comments. One header: s_max, bounds = the union.
//   preview.png      the result rendered from the scans (algorithms/parquetry/render.h)
//   report.json      pieces, grid, size, per sheet {id, pieces, used_mm2, free_mm2 after this
//                    job}, errors (reconstruction, baseline, target mean), seam costs, splits,
//                    laser figures, sheets_order, params (and working_px_per_mm, params.h)
// Not thread-safe per request; separate requests may run concurrently (the stock lock
// serialises those sharing a stock).
#pragma once

#include "convert/convert.h"

namespace atelier {

// The program a laser runs (every sheet's cuts and engraved IDs).
inline constexpr const char* kParquetryGcodeFile = "cuts.gcode";

// Throws ParamError (parameters, `wood` missing) and ConvertError (unreadable input or wood,
// out of wood with how much was needed, unfabricable shapes, a sheet larger than the laser's
// work area, no #ff0000 cut / #0000ff engrave layer, output files).
ConvertResult convert_parquetry(const ConvertRequest& request);

}  // namespace atelier
