// Tajima DST stitch files (see shared/protocols/embroidery-formats.md): a 512-byte ASCII
// header, then 3-byte balanced-ternary records, moves within +-121 units of 0.1 mm, +y up.
// The file's start point is the plan's origin (0, 0 mm). Pure, thread-safe.
#pragma once

#include <string>

#include "algorithms/embroidery/stitch_plan.h"

namespace atelier::embroidery {

// Returns the bytes of a DST file for `plan`:
// - positions rounded to 0.1 mm (rounding does not accumulate), image y flipped;
// - a stitch longer than 121 units becomes the fewest equal stitches each <= 121; a longer
//   jump becomes several jumps;
// - trim = jumps (+2,+2), (-4,-4), (+2,+2) (DST has no trim code); colour change 00 00 C3;
//   one end record 00 00 F3 always written last;
// - header ST = every body record including the end record (as common readers count),
//   CO = colour changes, +X/-X/+Y/-Y = extents of all positions the body reaches (including
//   the start point and trim jiggles) from the start point, AX/AY = end offset from start;
//   LA = plan.name, 16 characters, space padded, characters outside printable ASCII as '_'.
// Throws std::invalid_argument for an invalid plan (validate_plan) or one whose counts or
// extents do not fit the header's fields.
std::string write_dst(const StitchPlan& plan);

}  // namespace atelier::embroidery
