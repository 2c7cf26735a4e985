// Text on the printable charts (knit chart.pdf, lace chart.svg/pdf): DejaVu Sans, as the
// install script provides it. Thread-safe per cairo context.
#pragma once

#include <cairo.h>

#include <string>

namespace atelier {

// Draws `s` with its baseline at y, `size` in the surface's units (points for PDF); `align`
// places x at its left (0), centre (0.5) or right end (1).
void chart_text(cairo_t* cr, double x, double y, const std::string& s, double size, bool bold,
                double align = 0.0);

}  // namespace atelier
