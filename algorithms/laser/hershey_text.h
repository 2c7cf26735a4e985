// Single-stroke text for engraving part IDs, in the classic Hershey vector fonts.
//
// Glyphs come from Debian's hershey-fonts-data (.jhf files in /usr/share/hershey-fonts, or in
// $HERSHEY_FONTS_DIR when set, as libhersheyfont documents) parsed by libhersheyfont. Every
// stroke is an open polyline: the beam traces the letter once instead of filling an outline,
// which keeps IDs on veneer fast and legible down to a few mm.
//
// Units: mm. Design coordinates as in geometry.h: x right, y DOWN (like SVG).
// Threading: thread-safe. Each font file is read once, on first use, under a mutex, and kept
// for the life of the process; later calls only read the immutable cache.
// Errors: std::runtime_error for a font that cannot be read (the message names the path),
// std::invalid_argument for a character the font has no glyph for or a bad size.
#pragma once

#include <string>
#include <vector>

#include "algorithms/laser/geometry.h"

namespace atelier::laser {

// Strokes of `text` (printable ASCII, 32..126) starting at `baseline_left`: the left edge of
// the first glyph's advance box on the baseline. `cap_height_mm` is the height of a capital
// (the font's 'H'); digits have the same height in the Roman fonts. `angle_deg` turns the text
// about `baseline_left`, counter-clockwise as seen on the sheet (90: the text reads upwards).
// `font` is a .jhf name without extension ("rowmans", "futural", "rowmand", ...).
// Every returned path is open (closed == false) with at least 2 points; a dot or 'O' is a
// polyline whose last point repeats its first. Spaces advance without strokes.
std::vector<Path> hershey_text(const std::string& text, Point baseline_left, double cap_height_mm,
                               double angle_deg = 0, const std::string& font = "rowmans");

// Bounds of the ink (the stroke vertices) of hershey_text with the same arguments; empty for
// text without strokes. The beam's own width is not included.
Bounds hershey_text_bounds(const std::string& text, Point baseline_left, double cap_height_mm,
                           double angle_deg = 0, const std::string& font = "rowmans");

// Advance width of `text` along the baseline in mm: the sum of the glyphs' advances, including
// the side bearings (the ink is a little narrower; see hershey_text_bounds).
double hershey_text_advance(const std::string& text, double cap_height_mm,
                            const std::string& font = "rowmans");

// hershey_text placed so that the centre of its ink box (before rotation) lands on `centre`,
// then turned by `angle_deg` about that centre: an ID centred in a patch.
std::vector<Path> hershey_text_centred(const std::string& text, Point centre, double cap_height_mm,
                                       double angle_deg = 0, const std::string& font = "rowmans");

}  // namespace atelier::laser
