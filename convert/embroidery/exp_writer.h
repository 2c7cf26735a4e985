// Melco EXP stitch files (see shared/protocols/embroidery-formats.md): no header; a stitch is
// 2 signed bytes (dx, dy) in -127..+127 units of 0.1 mm; control records start with 0x80.
// +y is up, as in DST: common readers (e.g. pyembroidery, Embird) flip EXP's y like DST's, so
// the writer flips the image's y. The file's start point is the plan's origin (0, 0 mm).
// End of file: EXP has no end code; readers stop at the end of the file, so the writer writes
// nothing after the last record (an invented end code such as JEF's 80 10 would be read as an
// unknown control or a stray stitch by other readers). Pure, thread-safe.
#pragma once

#include <string>

#include "algorithms/embroidery/stitch_plan.h"

namespace atelier::embroidery {

// Returns the bytes of an EXP file for `plan`: positions rounded to 0.1 mm (rounding does not
// accumulate); a stitch longer than 127 units becomes the fewest equal stitches each <= 127,
// a longer jump several jumps (80 04 dx dy); trim 80 80 07 00; colour change 80 01 00 00;
// an `end` point writes nothing. Throws std::invalid_argument for an invalid plan
// (validate_plan).
std::string write_exp(const StitchPlan& plan);

}  // namespace atelier::embroidery
