#include "convert/knit/knit_chart.h"

#include <cairo-pdf.h>
#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "convert/common/cairo_output.h"
#include "convert/common/chart_text.h"
#include "convert/common/output_files.h"

namespace atelier {
namespace {

constexpr double kMm = 72.0 / 25.4;  // points per millimetre
constexpr double kPageW = 210 * kMm, kPageH = 297 * kMm;
constexpr double kMargin = 12 * kMm;
constexpr double kCell = 4.5 * kMm;
constexpr double kGutter = 9 * kMm;   // row numbers left and right of the grid
constexpr double kHeader = 27 * kMm;  // title, details, page range, colour key
constexpr double kFooter = 7 * kMm;   // stitch numbers under the grid

constexpr int kColsPerPage = static_cast<int>((kPageW - 2 * kMargin - 2 * kGutter) / kCell);
constexpr int kRowsPerPage =
    static_cast<int>((kPageH - 2 * kMargin - kHeader - kFooter) / kCell);

struct Tile {
  int row0, row1;      // pattern rows, 1 = bottom, inclusive
  int stitch0, stitch1;  // stitches counted from the right, inclusive
};

void set_rgb(cairo_t* cr, const Rgb& c) {
  cairo_set_source_rgb(cr, c.r / 255.0, c.g / 255.0, c.b / 255.0);
}

void draw_page(cairo_t* cr, const cv::Mat& grid, const ChartInfo& info, const Tile& t,
               int page, int pages) {
  const int rows = grid.rows, width = grid.cols;
  const int ncols = t.stitch1 - t.stitch0 + 1, nrows = t.row1 - t.row0 + 1;

  cairo_set_source_rgb(cr, 0, 0, 0);
  double y = kMargin + 5 * kMm;
  chart_text(cr, kMargin, y, info.title + " - Fair Isle chart", 13, true);
  y += 5.5 * kMm;
  chart_text(cr, kMargin, y,
       std::to_string(width) + " stitches x " + std::to_string(rows) + " rows   max float " +
           std::to_string(info.max_float) + "   solver " + info.solver,
       9, false);
  y += 4.5 * kMm;
  chart_text(cr, kMargin, y,
       "Page " + std::to_string(page) + " of " + std::to_string(pages) + ": rows " +
           std::to_string(t.row0) + "-" + std::to_string(t.row1) + ", stitches " +
           std::to_string(t.stitch0) + "-" + std::to_string(t.stitch1) +
           "   (row 1 = bottom, knitted first; stitches counted from the right)",
       8, false);
  if (info.first_row_top) {
    y += 3.5 * kMm;
    chart_text(cr, kMargin, y,
               "Knitted top-down: row 1 is the top of the picture, so the picture is upside down "
               "here, as the fabric comes off the machine.",
               8, false);
  }
  y += 3 * kMm;
  // Colour key.
  const char* labels[2] = {"background yarn (carrier 1)", "contrast yarn (carrier 2)"};
  double x = kMargin;
  for (int i = 0; i < 2; ++i) {
    cairo_rectangle(cr, x, y, 4 * kMm, 4 * kMm);
    set_rgb(cr, info.colors[i]);
    cairo_fill_preserve(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 0.5);
    cairo_stroke(cr);
    chart_text(cr, x + 5.5 * kMm, y + 3.2 * kMm, std::string(labels[i]) + " " + info.color_names[i],
         8, false);
    x += 80 * kMm;
  }

  // Grid: top-left corner; the top row of the tile is row1, the leftmost column stitch1.
  const double gx = kMargin + kGutter, gy = kMargin + kHeader;
  // One fill for the background and one path for all contrast cells: small, fast PDFs.
  set_rgb(cr, info.colors[0]);
  cairo_rectangle(cr, gx, gy, ncols * kCell, nrows * kCell);
  cairo_fill(cr);
  for (int r = 0; r < nrows; ++r) {
    int n = t.row1 - r;                            // chart row, 1 = knitted first
    const unsigned char* line = grid.ptr<unsigned char>(info.first_row_top ? n - 1 : rows - n);
    for (int k = 0; k < ncols;) {  // one rectangle per run of contrast cells
      int s = t.stitch1 - k;         // stitch from the right, at column width - s
      if (!line[width - s]) {
        ++k;
        continue;
      }
      int end = k;
      while (end < ncols && line[width - (t.stitch1 - end)]) ++end;
      cairo_rectangle(cr, gx + k * kCell, gy + r * kCell, (end - k) * kCell, kCell);
      k = end;
    }
  }
  set_rgb(cr, info.colors[1]);
  cairo_fill(cr);
  cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
  for (int k = 0; k <= ncols; ++k) {  // vertical line left of column k
    int s = t.stitch1 - k;  // the stitch right of this line
    bool bold = s % 10 == 0 && s > 0;
    cairo_set_line_width(cr, bold ? 1.2 : 0.3);
    cairo_move_to(cr, gx + k * kCell, gy);
    cairo_line_to(cr, gx + k * kCell, gy + nrows * kCell);
    cairo_stroke(cr);
  }
  for (int r = 0; r <= nrows; ++r) {  // horizontal line below tile row r-1
    int below = t.row1 - r;           // the line separates rows below and below+1
    bool bold = below % 10 == 0 && below > 0;
    cairo_set_line_width(cr, bold ? 1.2 : 0.3);
    cairo_move_to(cr, gx, gy + r * kCell);
    cairo_line_to(cr, gx + ncols * kCell, gy + r * kCell);
    cairo_stroke(cr);
  }

  // Row numbers: odd (right-side) rows on the right, even (wrong-side) rows on the left.
  cairo_set_source_rgb(cr, 0, 0, 0);
  for (int r = 0; r < nrows; ++r) {
    int n = t.row1 - r;
    double cy = gy + r * kCell + kCell * 0.7;
    bool bold = n % 10 == 0;
    if (n % 2 == 1) chart_text(cr, gx + ncols * kCell + 1.5 * kMm, cy, std::to_string(n), 6.5, bold);
    else chart_text(cr, gx - 1.5 * kMm, cy, std::to_string(n), 6.5, bold, 1.0);
  }
  // Stitch numbers: the first of the page and every 5th.
  for (int k = 0; k < ncols; ++k) {
    int s = t.stitch1 - k;
    if (s % 5 != 0 && s != t.stitch0) continue;
    chart_text(cr, gx + (k + 0.5) * kCell, gy + nrows * kCell + 4 * kMm, std::to_string(s), 6,
         s % 10 == 0, 0.5);
  }
}

// The pages in the order they are knitted: bottom rows first, then right to left.
std::vector<Tile> chart_tiles(const cv::Mat& grid) {
  std::vector<Tile> tiles;
  for (int r0 = 1; r0 <= grid.rows; r0 += kRowsPerPage)
    for (int s0 = 1; s0 <= grid.cols; s0 += kColsPerPage)
      tiles.push_back(Tile{r0, std::min(grid.rows, r0 + kRowsPerPage - 1), s0,
                           std::min(grid.cols, s0 + kColsPerPage - 1)});
  return tiles;
}

}  // namespace

cv::Mat render_chart_page(const cv::Mat& grid, const ChartInfo& info, int page, double px_per_mm) {
  CV_Assert(grid.type() == CV_8UC1 && !grid.empty() && px_per_mm > 0);
  const std::vector<Tile> tiles = chart_tiles(grid);
  if (page < 1 || page > static_cast<int>(tiles.size()))
    throw std::out_of_range("the chart has pages 1 to " + std::to_string(tiles.size()) + ", not " +
                            std::to_string(page));
  const double scale = px_per_mm / kMm;  // pixels per point
  cv::Mat bgra(static_cast<int>(std::ceil(kPageH * scale)), static_cast<int>(std::ceil(kPageW * scale)), CV_8UC4,
               cv::Scalar(255, 255, 255, 255));
  // Cairo's ARGB32 is B, G, R, A in memory on little-endian machines: OpenCV's BGRA.
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface(
      cairo_image_surface_create_for_data(bgra.data, CAIRO_FORMAT_ARGB32, bgra.cols, bgra.rows,
                                          static_cast<int>(bgra.step)),
      cairo_surface_destroy);
  {
    std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surface.get()), cairo_destroy);
    cairo_scale(cr.get(), scale, scale);
    draw_page(cr.get(), grid, info, tiles[static_cast<size_t>(page - 1)], page, static_cast<int>(tiles.size()));
  }
  cairo_surface_flush(surface.get());
  cv::Mat bgr;
  cv::cvtColor(bgra, bgr, cv::COLOR_BGRA2BGR);
  return bgr;
}

int write_chart_pdf(const cv::Mat& grid, const ChartInfo& info,
                    const std::filesystem::path& pdf) {
  CV_Assert(grid.type() == CV_8UC1 && !grid.empty());
  const std::vector<Tile> tiles = chart_tiles(grid);

  // Drawn into memory, then written atomically (cairo_output.h).
  CairoBytes bytes;
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface(
      cairo_pdf_surface_create_for_stream(CairoBytes::write, &bytes, kPageW, kPageH),
      cairo_surface_destroy);
  auto check = [&pdf](cairo_status_t status) {
    if (status != CAIRO_STATUS_SUCCESS)
      throw ConvertError(pdf.filename().string() + ": cannot write: " + cairo_status_to_string(status));
  };
  check(cairo_surface_status(surface.get()));
  cairo_pdf_surface_set_metadata(surface.get(), CAIRO_PDF_METADATA_TITLE,
                                 (info.title + " - Fair Isle chart").c_str());
  cairo_pdf_surface_set_metadata(surface.get(), CAIRO_PDF_METADATA_CREATOR, "atelier");
  {
    std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surface.get()),
                                                          cairo_destroy);
    for (size_t i = 0; i < tiles.size(); ++i) {
      draw_page(cr.get(), grid, info, tiles[i], static_cast<int>(i) + 1,
                static_cast<int>(tiles.size()));
      cairo_show_page(cr.get());
      if (info.progress) info.progress(static_cast<double>(i + 1) / tiles.size());
    }
    check(cairo_status(cr.get()));
  }
  cairo_surface_finish(surface.get());
  check(cairo_surface_status(surface.get()));
  write_output(pdf, bytes.bytes);
  return static_cast<int>(tiles.size());
}

}  // namespace atelier
