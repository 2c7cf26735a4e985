// The thread tables of the home machines' formats, and the nearest thread to a design colour.
// PES/PEC (Brother) and JEF (Janome) carry no RGB: each colour block names a thread by its index
// in the maker's fixed table, and the machine shows that thread's name and colour to the
// operator. The tables are the makers' as published in the format descriptions (the same
// values libembroidery and pyembroidery use). Colours are 0xRRGGBB. Pure, thread-safe (the
// tables are immutable statics).
#pragma once

#include <cstdint>
#include <vector>

#include "algorithms/embroidery/stitch_plan.h"

namespace atelier::embroidery {

struct Thread {
  std::uint32_t rgb;   // 0xRRGGBB
  const char* name;    // as the machine shows it ("Prussian Blue")
  const char* code;    // the maker's catalogue number
};

// Brother's PEC table: file index i (1..64) is pec_threads()[i - 1]. Index 0 is unused.
const std::vector<Thread>& pec_threads();
// Janome's JEF table: file index i (1..78) is jef_threads()[i - 1]. Index 0 means "stop".
const std::vector<Thread>& jef_threads();

// CIE76 colour difference (dE*ab) of two sRGB colours in CIELAB (D65): perceptual, so a
// yellow is not matched to an olive that is merely close in RGB.
double color_difference(std::uint32_t rgb_a, std::uint32_t rgb_b);

// File index (1-based) of the thread of `table` nearest to `rgb` (smallest color_difference;
// ties: the lower index).
int nearest_thread(const std::vector<Thread>& table, std::uint32_t rgb);

// File indices (1-based) for the colour blocks' colours, in order: each colour gets its
// nearest thread, except that a colour different from an earlier one whose nearest thread
// that earlier colour already took gets its nearest thread not yet taken (so distinct design
// colours stay distinct on the machine's screen while the table has threads left); equal
// colours share their thread.
std::vector<int> assign_threads(const std::vector<Thread>& table, const std::vector<std::uint32_t>& colors);

// The colour of each colour block of `plan` (colour changes + 1 blocks): plan.colors_rgb[i],
// or the last listed colour (black when none is listed) for a block the list does not reach.
std::vector<std::uint32_t> block_colors(const StitchPlan& plan);

}  // namespace atelier::embroidery
