// Janome JEF stitch files, see shared/protocols/embroidery-formats.md: a 116-byte header (offset,
// flags, date, thread count, stitch count, hoop code, extents, distances to the edges of
// Janome's hoops), the thread indices into Janome's 78-thread table (thread_palettes.h), then
// 2-byte records. Units: 0.1 mm, +y up (JEF flips the image's y, as DST and EXP). The file's
// start point is the plan's origin (0, 0 mm), which Janome's machines put at the hoop's
// centre. Pure, thread-safe.
#pragma once

#include <string>
#include <vector>

#include "algorithms/embroidery/stitch_plan.h"

namespace atelier::embroidery {

// Janome's hoops: the header's hoop code and size in 0.1 mm.
struct JefHoop {
  int code;
  long width, height;
};
// The hoops in the order the writer tries them (smallest first): 50 x 50 (code 1),
// 110 x 110 (0), 126 x 110 (3), 140 x 200 (2), 200 x 200 (4).
const std::vector<JefHoop>& jef_hoops();

// Returns the bytes of a JEF file for `plan`, dated `date` ("YYYYMMDDhhmmss", 14 digits:
// the writer reads no clock):
// - header (all u32 LE unless said): offset of the first record (0x74 + 8 x threads), 0x14,
//   the date (14 ASCII bytes) and 2 zero bytes, thread count (colour blocks), stitch count
//   (body length / 2, as Janome counts: a stitch 1, a control record 2, the end 1), the hoop
//   code of the smallest Janome hoop the design fits centred on the start point (200 x 200
//   when none does: the hoop check is the planner's, against the configured hoop), the
//   extents left, top, right, bottom from the start point, then for the 110 x 110, 50 x 50
//   and 140 x 200 hoops and the chosen one the distances from the design to the hoop's left,
//   top, right and bottom edges (-1 four times when it does not fit); the thread index of each
//   colour block (nearest thread in CIELAB, distinct colours kept distinct: assign_threads),
//   then 0x0D once per block;
// - records: positions rounded to 0.1 mm (rounding does not accumulate); a stitch is dx, dy
//   as signed bytes; a move longer than 127 becomes several (split_move); jump 80 02 dx dy;
//   trim 80 02 00 00 three times (JEF's trim is a zero jump; machines set to trim on jumps
//   count three); colour change 80 01 00 00; end 80 10, written once, last.
// Throws std::invalid_argument for an invalid plan (validate_plan) or a malformed date.
std::string write_jef(const StitchPlan& plan, const std::string& date);

}  // namespace atelier::embroidery
