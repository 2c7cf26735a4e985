// Brother PES version 1 stitch files (`#PES0001`, read by every Brother home machine), see
// shared/protocols/embroidery-formats.md. A PES file is a small PES part (what PE-Design
// edits: one CEmbOne/CSewSeg block set, absolute coordinates) and the PEC section the
// machine sews from: label, colour count and thread indices into Brother's 64-thread table
// (thread_palettes.h), the stitches as relative moves, and 48x38 1-bit thumbnails (the whole
// design, then one per colour block, as machines show them).
// Units: 0.1 mm, image frame (+y DOWN: PEC does not flip y, unlike DST and EXP). The file's
// start point is the plan's origin (0, 0 mm). Pure, thread-safe.
#pragma once

#include <cstddef>
#include <string>

#include "algorithms/embroidery/stitch_plan.h"

namespace atelier::embroidery {

// PEC facts the writer and its tests share.
inline constexpr int kPecThumbWidth = 48, kPecThumbHeight = 38;  // pixels, 1 bit each
inline constexpr int kPecThumbBytes = kPecThumbWidth / 8 * kPecThumbHeight;  // 228, rows of 6 bytes
inline constexpr std::size_t kPecHeaderBytes = 512;  // label .. colour list; stitch block follows
inline constexpr long kPecMaxShort = 63, kPecMinShort = -64;  // 7-bit move
inline constexpr long kPecMaxLong = 2047;                     // 12-bit move, +-2047
inline constexpr int kPecMaxColors = 255;                     // colour blocks ("count - 1" is a byte)

// Returns the bytes of a PES v1 file for `plan`:
// - PES part: "#PES0001", the PEC offset (u32 LE), scale-to-fit 1, hoop 0 (100 x 100 mm)
//   when the design's extent fits it, else 1 (130 x 180 mm), one CEmbOne block (identity
//   affine placing the design at the hoop's centre, its width and height) and its CSewSeg
//   segments: runs of stitches (flag 0) and of jumps (flag 1, from the last stitch to the jump's
//   end), each with its colour block's thread index, points relative to the design's left and
//   bottom edges, then the colour log (first segment of each colour block, thread index);
// - PEC section at the PEC offset: "LA:" label (16 characters, as DST's), thumbnail stride 6
//   and height 38, colour count - 1 and the thread index of every colour block (nearest thread
//   in CIELAB, distinct colours kept distinct: assign_threads), padded to 512 bytes; then the
//   stitch block: 00 00, its length (u24 LE, from its first byte to the end code: the
//   thumbnails start there), 31 FF F0, width, height, 01E0, 01B0 (u16 LE), the moves and
//   FF; then 1 + colour blocks thumbnails of 228 bytes (bit x % 8 of byte y * 6 + x / 8);
// - moves: positions rounded to 0.1 mm (rounding does not accumulate); a stitch's dx and dy
//   each take 1 byte (7-bit, -64..63) or 2 (12-bit, high bit set); a jump is 12-bit on both
//   axes with the jump flag (0x10), or the trim flag (0x20) on the first move after a trim (a
//   trim with no jump after it is a trim-flagged zero move); any move longer than 2047
//   becomes several (split_move); colour change FE B0 02 / FE B0 01 alternately; end FF.
// Throws std::invalid_argument for an invalid plan (validate_plan), more than 255 colour
// blocks, more than 65535 CSewSeg segments, or a design whose extent does not fit the 16-bit
// size fields.
std::string write_pes(const StitchPlan& plan);

}  // namespace atelier::embroidery
