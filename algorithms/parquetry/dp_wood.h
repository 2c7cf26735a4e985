// Internal to refine = dp: the wood each cell's cuts may use beyond its core.
//
// A dp cell's core is matched and taken like a square of the regular grid, so with every cut
// straight the plan is the regular one. The window around the core (the overlap the cuts move
// in) is the wood around that core on its sheet, which other pieces may need too: a window
// pixel is available to its cell when the wood under its centre is
//   - in the cell's own core, or
//   - usable veneer not used by the stock (kerf included) a pixel in from its edges, at least
//     kerf + 2.2 px from every other core on the sheet, and nearer to this core than to any
//     other by kerf + 2 px.
// The last rule splits contested wood between neighbours on a sheet with a gap: since the
// difference of two distance functions changes by at most 2 per px, two pixels given to two
// different cells are at least kerf + 2 px apart, so pieces never come within the kerf of
// each other whatever their cuts do inside the available pixels (an outline covers at most
// half a pixel beyond the pixel centres it covers; the rest is the pixel's own slack).
//
// Units: working px (result and sheets at the plan's px_per_mm). Pure: reads the WoodIndex
// (const) and the sheets, changes nothing.
#pragma once

#include <vector>

#include "algorithms/parquetry/plan_shapes.h"

namespace atelier::parquetry {

// Per entry of `placed` (dp cells of every target planned on the wood): CV_8UC1 of its
// rect's size, 255 = the cuts may give that window pixel to the cell.
std::vector<cv::Mat> available_wood(const std::vector<const Placed*>& placed,
                                    const std::vector<Sheet>& sheets, const Stock& stock,
                                    const WoodIndex& wood, double px_per_mm, double kerf_mm);

}  // namespace atelier::parquetry
