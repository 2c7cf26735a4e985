#include "convert/lace/lace_chart.h"

#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "algorithms/lace/chart_layout.h"
#include "convert/common/cairo_output.h"
#include "convert/common/chart_text.h"
#include "convert/common/output_files.h"

namespace atelier {
namespace {

using lace::Chart;
using lace::Symbol;

constexpr double kMm = 72.0 / 25.4;  // points per millimetre
constexpr double kPageW = 210 * kMm, kPageH = 297 * kMm;
constexpr double kMargin = 12 * kMm;
constexpr double kMaxCell = 6 * kMm, kMinCell = 4 * kMm;
constexpr double kGutterRight = 9 * kMm;  // row numbers
constexpr double kGutterLeft = 3 * kMm;
constexpr double kLegendLine = 6 * kMm;
// Title, details, the legend (a line per symbol) and its note on double yarn-overs.
constexpr double kHeader = 17 * kMm + 7 * kLegendLine + 3 * kMm;
constexpr double kFooter = 7 * kMm;       // stitch numbers
constexpr double kLegendWidth = 150 * kMm;

struct LegendEntry {
  Symbol symbol;
  const char* name;
  const char* meaning;
};
constexpr LegendEntry kLegend[] = {
    {Symbol::k, "k", "RS: knit"},
    {Symbol::yo, "yo", "RS: yarn over (makes a stitch and a hole)"},
    {Symbol::k2tog, "k2tog", "RS: knit 2 together (right-slanting decrease)"},
    {Symbol::ssk, "ssk", "RS: slip, slip, knit the 2 slipped stitches together (left-slanting decrease)"},
    {Symbol::sk2p, "sk2p", "RS: slip 1, knit 2 together, pass slipped stitch over (left-slanting double decrease)"},
    {Symbol::s2kp, "s2kp", "RS: slip 2 together knitwise, knit 1, pass the 2 slipped stitches over (centred double decrease)"},
};
// Under the legend when the chart has two yarn-overs side by side (issue 22, lace point 3).
constexpr const char* kDoubleYarnOver =
    "Two yo side by side (double yarn-over): on the next WS row purl 1, knit 1 into it.";

bool has_double_yarn_over(const Chart& chart) {
  for (const lace::Row& r : chart.rows)
    if (lace::max_adjacent_yarn_overs(r, true) >= 2) return true;
  return false;
}

// A page's share of the chart: chart rows row0..row1 (0-based), columns col0..col1 counted
// from the right (0-based), all inclusive.
struct Tile {
  int row0, row1, col0, col1;
};

struct Page {
  double width, height, cell;
};


// The symbol inside the cell whose top-left corner is (x, y).
void draw_symbol(cairo_t* cr, Symbol s, double x, double y, double c) {
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, std::max(0.6, 0.09 * c));
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  switch (s) {
    case Symbol::k: return;  // the empty square
    case Symbol::yo:
      cairo_new_sub_path(cr);
      cairo_arc(cr, x + 0.5 * c, y + 0.5 * c, 0.3 * c, 0, 2 * 3.14159265358979);
      break;
    case Symbol::k2tog:  // "/": rising to the right
      cairo_move_to(cr, x + 0.2 * c, y + 0.8 * c);
      cairo_line_to(cr, x + 0.8 * c, y + 0.2 * c);
      break;
    case Symbol::ssk:  // "\": falling to the right
      cairo_move_to(cr, x + 0.2 * c, y + 0.2 * c);
      cairo_line_to(cr, x + 0.8 * c, y + 0.8 * c);
      break;
    case Symbol::sk2p:  // an inverted V leaning left: its apex over the left leg
      cairo_move_to(cr, x + 0.18 * c, y + 0.82 * c);
      cairo_line_to(cr, x + 0.25 * c, y + 0.18 * c);
      cairo_line_to(cr, x + 0.82 * c, y + 0.82 * c);
      break;
    case Symbol::s2kp:  // "^" with a vertical line through its apex: the centred double decrease
      cairo_move_to(cr, x + 0.18 * c, y + 0.82 * c);
      cairo_line_to(cr, x + 0.5 * c, y + 0.18 * c);
      cairo_line_to(cr, x + 0.82 * c, y + 0.82 * c);
      cairo_move_to(cr, x + 0.5 * c, y + 0.18 * c);
      cairo_line_to(cr, x + 0.5 * c, y + 0.85 * c);
      break;
  }
  cairo_stroke(cr);
}

// The grid's top-left corner: left-aligned under the header on every page.
constexpr double kGridX = kMargin + kGutterLeft;
constexpr double kGridY = kMargin + kHeader;

void draw_page(cairo_t* cr, const Chart& chart, const lace::ChartLayout& layout, int cast_on,
               const LaceChartInfo& info, const Page& p, const Tile& t, int page, int pages) {
  const double c = p.cell;
  const int ncols = t.col1 - t.col0 + 1, nrows = t.row1 - t.row0 + 1;
  const int rs_rows = static_cast<int>(chart.rows.size());

  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  double y = kMargin + 5 * kMm;
  chart_text(cr, kMargin, y, (info.title.empty() ? std::string("Lace") : info.title) + " - lace chart", 13, true);
  y += 5.5 * kMm;
  chart_text(cr, kMargin, y,
       "Multiple of " + std::to_string(cast_on) + " sts; " + std::to_string(2 * rs_rows) +
           " rows (right-side rows 1-" + std::to_string(2 * rs_rows - 1) +
           " shown; all wrong-side rows purl)",
       9, false);
  y += 4.5 * kMm;
  std::string where = "Read right to left from row 1 at the bottom; grey cells: no stitch.";
  if (pages > 1) {
    where = "Page " + std::to_string(page) + " of " + std::to_string(pages) + ": rows " +
            std::to_string(2 * t.row0 + 1) + "-" + std::to_string(2 * t.row1 + 1) + ", stitches " +
            std::to_string(t.col0 + 1) + "-" + std::to_string(t.col1 + 1) + ". " + where;
  }
  chart_text(cr, kMargin, y, where, 8, false);
  y += 3 * kMm;
  // Legend: the symbol in a cell, its abbreviation and what to do on a right-side row.
  const double lc = 4.5 * kMm;
  for (const LegendEntry& e : kLegend) {
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 0.5);
    cairo_rectangle(cr, kMargin, y, lc, lc);
    cairo_stroke(cr);
    draw_symbol(cr, e.symbol, kMargin, y, lc);
    cairo_set_source_rgb(cr, 0, 0, 0);
    chart_text(cr, kMargin + lc + 2.5 * kMm, y + 3.3 * kMm, e.name, 9, true);
    chart_text(cr, kMargin + lc + 15 * kMm, y + 3.3 * kMm, e.meaning, 8.5, false);
    y += kLegendLine;
  }
  if (has_double_yarn_over(chart)) {
    cairo_set_source_rgb(cr, 0, 0, 0);
    chart_text(cr, kMargin, y + 3.3 * kMm, kDoubleYarnOver, 8.5, false);
  }

  const double gx = kGridX, gy = kGridY;
  // Cells: column k from the right of the tile sits at gx + (t.col1 - k) * c.
  for (int r = t.row0; r <= t.row1; ++r) {
    const lace::Row& row = chart.rows[static_cast<std::size_t>(r)];
    const double cy = gy + (t.row1 - r) * c;
    for (int k = t.col0; k <= t.col1; ++k) {
      const double cx = gx + (t.col1 - k) * c;
      const int j = layout.cells[static_cast<std::size_t>(r)][static_cast<std::size_t>(k)];
      if (j < 0) {  // no stitch: a decrease not yet balanced by a yarn-over, or the reverse
        cairo_set_source_rgb(cr, 0.62, 0.62, 0.62);
        cairo_rectangle(cr, cx, cy, c, c);
        cairo_fill(cr);
      } else {
        draw_symbol(cr, row[static_cast<std::size_t>(j)], cx, cy, c);
      }
    }
  }
  cairo_set_source_rgb(cr, 0.2, 0.2, 0.2);
  for (int k = 0; k <= ncols; ++k) {
    const int s = t.col1 + 1 - k;  // stitches to the right of this line, counted from the right
    cairo_set_line_width(cr, s % 10 == 0 && s > 0 ? 1.1 : 0.35);
    cairo_move_to(cr, gx + k * c, gy);
    cairo_line_to(cr, gx + k * c, gy + nrows * c);
    cairo_stroke(cr);
  }
  for (int r = 0; r <= nrows; ++r) {
    cairo_set_line_width(cr, 0.35);
    cairo_move_to(cr, gx, gy + r * c);
    cairo_line_to(cr, gx + ncols * c, gy + r * c);
    cairo_stroke(cr);
  }
  // Row numbers (odd, right edge) and stitch numbers (from the right, along the bottom).
  cairo_set_source_rgb(cr, 0, 0, 0);
  const double font = std::clamp(0.42 * c, 5.0, 8.0);
  for (int r = t.row0; r <= t.row1; ++r) {
    chart_text(cr, gx + ncols * c + 1.5 * kMm, gy + (t.row1 - r) * c + 0.5 * c + 0.35 * font,
         std::to_string(2 * r + 1), font, false);
  }
  for (int k = t.col0; k <= t.col1; ++k) {
    const int s = k + 1;
    if (c < 5 * kMm && s % 5 != 0 && s != t.col0 + 1) continue;  // small cells: every 5th
    chart_text(cr, gx + (t.col1 - k + 0.5) * c, gy + nrows * c + 4 * kMm, std::to_string(s), font,
         false, 0.5);
  }
}

void check_chart(const Chart& chart, int cast_on) {
  if (const lace::Knittability k = lace::knittable(chart, cast_on); !k)
    throw std::invalid_argument("lace chart: " + k.why);
}

Page single_page(const Chart& chart, const lace::ChartLayout& layout, double cell) {
  const int cols = layout.columns, rows = static_cast<int>(chart.rows.size());
  return Page{std::max(kLegendWidth, cols * cell + kGutterLeft + kGutterRight) + 2 * kMargin,
              kGridY + rows * cell + kFooter + kMargin, cell};
}

void check(cairo_status_t status) {
  if (status != CAIRO_STATUS_SUCCESS) throw std::runtime_error(cairo_status_to_string(status));
}

// As check(), for a document bound for `file`: the error names it.
void check_file(cairo_status_t status, const std::filesystem::path& file) {
  if (status != CAIRO_STATUS_SUCCESS)
    throw ConvertError(file.string() + ": " + cairo_status_to_string(status));
}

using SurfacePtr = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;
using CairoPtr = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char ch : s) {
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += ch;
    }
  }
  return out;
}

}  // namespace

void write_lace_chart_svg(const Chart& chart, int cast_on, const LaceChartInfo& info,
                          const std::filesystem::path& svg) {
  check_chart(chart, cast_on);
  const lace::ChartLayout layout = lace::layout_chart(chart, cast_on);
  const Page p = single_page(chart, layout, kMaxCell);
  const Tile all{0, static_cast<int>(chart.rows.size()) - 1, 0, layout.columns - 1};
  CairoBytes bytes;  // drawn into memory, then written atomically (cairo_output.h)
  {
    SurfacePtr surface(cairo_svg_surface_create_for_stream(CairoBytes::write, &bytes, p.width, p.height),
                       cairo_surface_destroy);
    check_file(cairo_surface_status(surface.get()), svg);
    {
      CairoPtr cr(cairo_create(surface.get()), cairo_destroy);
      draw_page(cr.get(), chart, layout, cast_on, info, p, all, 1, 1);
      check_file(cairo_status(cr.get()), svg);
    }
    cairo_surface_finish(surface.get());
    check_file(cairo_surface_status(surface.get()), svg);
  }
  // cairo writes text as glyph outlines: add the title and legend as text for readers.
  std::string& doc = bytes.bytes;
  const std::size_t open = doc.find("<svg");
  const std::size_t end = open == std::string::npos ? open : doc.find('>', open);
  if (end == std::string::npos) throw ConvertError(svg.string() + ": cairo wrote no <svg> element");
  std::string desc = "Multiple of " + std::to_string(cast_on) + " sts, " +
                     std::to_string(2 * chart.rows.size()) + " rows. Legend:";
  for (const LegendEntry& e : kLegend) desc += std::string(" ") + e.name + " - " + e.meaning + ";";
  if (has_double_yarn_over(chart)) desc += std::string(" ") + kDoubleYarnOver;
  doc.insert(end + 1, "\n<title>" +
                          xml_escape((info.title.empty() ? std::string("Lace") : info.title) +
                                     " - lace chart") +
                          "</title>\n<desc>" + xml_escape(desc) + "</desc>");
  write_output(svg, doc);
}

int write_lace_chart_pdf(const Chart& chart, int cast_on, const LaceChartInfo& info,
                         const std::filesystem::path& pdf) {
  check_chart(chart, cast_on);
  const lace::ChartLayout layout = lace::layout_chart(chart, cast_on);
  const int cols = layout.columns, rows = static_cast<int>(chart.rows.size());
  const double avail_w = kPageW - 2 * kMargin - kGutterLeft - kGutterRight;
  const double avail_h = kPageH - kMargin - kGridY - kFooter;
  double cell = std::min({kMaxCell, avail_w / cols, avail_h / rows});
  std::vector<Tile> tiles;
  if (cell >= kMinCell) {
    tiles.push_back(Tile{0, rows - 1, 0, cols - 1});
  } else {
    cell = kMinCell;
    const int per_row = static_cast<int>(avail_w / cell), per_col = static_cast<int>(avail_h / cell);
    for (int c0 = 0; c0 < cols; c0 += per_row)
      for (int r0 = 0; r0 < rows; r0 += per_col)
        tiles.push_back(Tile{r0, std::min(rows, r0 + per_col) - 1, c0, std::min(cols, c0 + per_row) - 1});
    // Bottom rows first, then right to left: the order in which they are knitted.
    std::stable_sort(tiles.begin(), tiles.end(), [](const Tile& a, const Tile& b) {
      return a.row0 != b.row0 ? a.row0 < b.row0 : a.col0 < b.col0;
    });
  }
  const Page p{kPageW, kPageH, cell};
  CairoBytes bytes;  // drawn into memory, then written atomically (cairo_output.h)
  SurfacePtr surface(cairo_pdf_surface_create_for_stream(CairoBytes::write, &bytes, kPageW, kPageH),
                     cairo_surface_destroy);
  check_file(cairo_surface_status(surface.get()), pdf);
  const std::string title = (info.title.empty() ? std::string("Lace") : info.title) + " - lace chart";
  cairo_pdf_surface_set_metadata(surface.get(), CAIRO_PDF_METADATA_TITLE, title.c_str());
  cairo_pdf_surface_set_metadata(surface.get(), CAIRO_PDF_METADATA_CREATOR, "atelier");
  {
    CairoPtr cr(cairo_create(surface.get()), cairo_destroy);
    for (std::size_t i = 0; i < tiles.size(); ++i) {
      draw_page(cr.get(), chart, layout, cast_on, info, p, tiles[i], static_cast<int>(i) + 1,
                static_cast<int>(tiles.size()));
      cairo_show_page(cr.get());
    }
    check_file(cairo_status(cr.get()), pdf);
  }
  cairo_surface_finish(surface.get());
  check_file(cairo_surface_status(surface.get()), pdf);
  write_output(pdf, bytes.bytes);
  return static_cast<int>(tiles.size());
}

LaceChartRaster render_lace_chart_png(const Chart& chart, int cast_on, const LaceChartInfo& info,
                                      double px_per_mm) {
  check_chart(chart, cast_on);
  const lace::ChartLayout layout = lace::layout_chart(chart, cast_on);
  const Page p = single_page(chart, layout, kMaxCell);
  const Tile all{0, static_cast<int>(chart.rows.size()) - 1, 0, layout.columns - 1};
  const double scale = px_per_mm / kMm;  // pixels per point
  const int w = static_cast<int>(std::ceil(p.width * scale)), h = static_cast<int>(std::ceil(p.height * scale));
  SurfacePtr surface(cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h), cairo_surface_destroy);
  check(cairo_surface_status(surface.get()));
  {
    CairoPtr cr(cairo_create(surface.get()), cairo_destroy);
    cairo_scale(cr.get(), scale, scale);
    draw_page(cr.get(), chart, layout, cast_on, info, p, all, 1, 1);
    check(cairo_status(cr.get()));
  }
  cairo_surface_flush(surface.get());
  LaceChartRaster out;
  const cv::Mat bgra(h, w, CV_8UC4, cairo_image_surface_get_data(surface.get()),
                     static_cast<std::size_t>(cairo_image_surface_get_stride(surface.get())));
  cv::cvtColor(bgra, out.image, cv::COLOR_BGRA2BGR);
  const double gx = kGridX, gy = kGridY;
  for (int r = 0; r <= all.row1; ++r) {
    std::vector<cv::Rect2d> cells;
    for (std::size_t j = 0; j < chart.rows[static_cast<std::size_t>(r)].size(); ++j) {
      const int k = layout.column[static_cast<std::size_t>(r)][j];
      cells.emplace_back((gx + (all.col1 - k) * p.cell) * scale,
                         (gy + (all.row1 - r) * p.cell) * scale, p.cell * scale, p.cell * scale);
    }
    out.cells.push_back(std::move(cells));
    std::vector<cv::Rect2d> grid;
    for (int k = 0; k < layout.columns; ++k)
      grid.emplace_back((gx + (all.col1 - k) * p.cell) * scale, (gy + (all.row1 - r) * p.cell) * scale,
                        p.cell * scale, p.cell * scale);
    out.grid.push_back(std::move(grid));
  }
  return out;
}

}  // namespace atelier
