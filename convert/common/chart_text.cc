#include "convert/common/chart_text.h"

#include "convert/common/display_text.h"

namespace atelier {

void chart_text(cairo_t* cr, double x, double y, const std::string& s, double size, bool bold,
                double align) {
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
  cairo_text_extents_t ext;
  // Cairo refuses text that is not UTF-8 (and would stop the whole document): names are data.
  const std::string text = safe_text(s);
  cairo_text_extents(cr, text.c_str(), &ext);
  cairo_move_to(cr, x - align * ext.x_advance, y);
  cairo_show_text(cr, text.c_str());
}

}  // namespace atelier
