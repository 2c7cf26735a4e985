// Single-stroke text for engraving part IDs, in the classic Hershey vector fonts.
//
// The font's glyphs are data passed in (HersheyFont); reading them from Debian's
// hershey-fonts-data is convert/common/hershey_fonts.h's job, so this stays pure. Every
// stroke is an open polyline: the beam traces the letter once instead of filling an outline,
// which keeps IDs on veneer fast and legible down to a few mm.
//
// Units: mm. Design coordinates as in geometry.h: x right, y DOWN (like SVG).
// Threading: thread-safe (no shared state); the font is only read.
// Errors: std::invalid_argument for a character the font has no glyph for or a bad size.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "algorithms/laser/geometry.h"

namespace atelier::laser {

// One glyph in font units: x right from the glyph's left bearing, y UP from the baseline
// (libhersheyfont's frame).
struct HersheyGlyph {
  bool present = false;  // the font has a glyph for this character
  int advance = 0;       // font units
  std::vector<std::vector<Point>> strokes;  // each at least 2 points
};

// A font's 7-bit ASCII glyphs, indexed by character.
struct HersheyFont {
  std::string name;  // "rowmans", ... (for messages)
  std::array<HersheyGlyph, 128> glyphs;
  double cap_units = 21;  // height of 'H'; 21 in every Roman Hershey font
};

// Strokes of `text` (printable ASCII, 32..126) starting at `baseline_left`: the left edge of
// the first glyph's advance box on the baseline. `cap_height_mm` is the height of a capital
// (the font's 'H'); digits have the same height in the Roman fonts. `angle_deg` turns the text
// about `baseline_left`, counter-clockwise as seen on the sheet (90: the text reads upwards).
// Every returned path is open (closed == false) with at least 2 points; a dot or 'O' is a
// polyline whose last point repeats its first. Spaces advance without strokes.
std::vector<Path> hershey_text(const HersheyFont& font, const std::string& text, Point baseline_left,
                               double cap_height_mm, double angle_deg = 0);

// Bounds of the ink (the stroke vertices) of hershey_text with the same arguments; empty for
// text without strokes. The beam's own width is not included.
Bounds hershey_text_bounds(const HersheyFont& font, const std::string& text, Point baseline_left,
                           double cap_height_mm, double angle_deg = 0);

// Advance width of `text` along the baseline in mm: the sum of the glyphs' advances, including
// the side bearings (the ink is a little narrower; see hershey_text_bounds).
double hershey_text_advance(const HersheyFont& font, const std::string& text, double cap_height_mm);

// hershey_text placed so that the centre of its ink box (before rotation) lands on `centre`,
// then turned by `angle_deg` about that centre: an ID centred in a patch.
std::vector<Path> hershey_text_centred(const HersheyFont& font, const std::string& text, Point centre,
                                       double cap_height_mm, double angle_deg = 0);

}  // namespace atelier::laser
