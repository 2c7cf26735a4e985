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

constexpr double kMapLine = 3.0 * kMm;  // one page-map line
constexpr int kMapEntriesPerLine = 10;  // stitch ranges per line (fits 186 mm at 6 pt)
constexpr int kMapRowsPerLine = 5;      // "rows 1-51 p.1-10" per line
constexpr int kMapMaxRowEntries = 2 * kMapRowsPerLine;  // longer lists are shortened

constexpr int kColsPerPage = static_cast<int>((kPageW - 2 * kMargin - 2 * kGutter) / kCell);
constexpr int kRowsPerPageNoMap =
    static_cast<int>((kPageH - 2 * kMargin - kHeader - kFooter) / kCell);

using Tile = ChartTile;

int ceil_div(int a, int b) { return (a + b - 1) / b; }

// `n` items split into `parts` consecutive bands whose sizes differ by at most one (the
// first bands take the extra ones): first and last item of each, 1-based.
std::vector<std::pair<int, int>> even_bands(int n, int parts) {
  std::vector<std::pair<int, int>> bands;
  const int base = n / parts, extra = n % parts;
  for (int i = 0, first = 1; i < parts; ++i) {
    const int size = base + (i < extra ? 1 : 0);
    bands.push_back({first, first + size - 1});
    first += size;
  }
  return bands;
}

int page_columns(int stitches) { return ceil_div(stitches, kColsPerPage); }

// Lines the page map takes (0 for one page): the stitch list wrapped, the row list wrapped. The map is under the header of every page so all pages hold as many
// rows; rows per page and map lines depend on each other, so settle it by iterating from
// the map's largest size (bounded: at most a few steps).
int map_lines_for(int column_bands, int row_bands) {
  if (column_bands * row_bands <= 1) return 0;
  const int row_entries = std::min(row_bands, kMapMaxRowEntries + 1);
  return ceil_div(column_bands, kMapEntriesPerLine) + ceil_div(row_entries, kMapRowsPerLine);
}

int rows_per_page(int map_lines) {
  return static_cast<int>((kPageH - 2 * kMargin - kHeader - map_lines * kMapLine - kFooter) / kCell);
}

struct Layout {
  std::vector<std::pair<int, int>> stitch_bands, row_bands;
  int map_lines = 0;
};

Layout make_layout(int stitches, int rows) {
  Layout l;
  const int across = page_columns(stitches);
  l.stitch_bands = even_bands(stitches, across);
  int down = ceil_div(rows, kRowsPerPageNoMap);
  l.map_lines = map_lines_for(across, down);
  for (int step = 0; step < 4; ++step) {  // converges in one or two steps
    down = ceil_div(rows, rows_per_page(l.map_lines));
    const int lines = map_lines_for(across, down);
    if (lines <= l.map_lines) break;
    l.map_lines = lines;
  }
  l.row_bands = even_bands(rows, down);
  return l;
}

std::string range(const std::pair<int, int>& b) {
  return b.first == b.second ? std::to_string(b.first)
                             : std::to_string(b.first) + "-" + std::to_string(b.second);
}

std::vector<std::string> page_map_lines(const Layout& l) {
  std::vector<std::string> lines;
  const int across = static_cast<int>(l.stitch_bands.size());
  const int down = static_cast<int>(l.row_bands.size());
  if (across * down <= 1) return lines;
  // `entries` joined by " | ", `per_line` to a line, the first line led by `lead`.
  auto wrap = [&lines](const std::string& lead, const std::vector<std::string>& entries, int per_line) {
    std::string line = lead;
    for (size_t i = 0; i < entries.size(); ++i) {
      if (i > 0 && i % per_line == 0) {
        lines.push_back(line);
        line = "      ";
      }
      line += (i % per_line == 0 ? "" : "  |  ") + entries[i];
    }
    lines.push_back(line);
  };
  std::vector<std::string> cols;
  for (int c = 0; c < across; ++c) cols.push_back(range(l.stitch_bands[c]));
  wrap(across == 1 ? "Page map: every page stitches " : "Page map: stitches ", cols, kMapEntriesPerLine);
  std::vector<std::string> bands;
  auto band = [&](int r) {
    const int first = r * across + 1, last = first + across - 1;
    return "rows " + range(l.row_bands[r]) + (across == 1 ? " p." + std::to_string(first)
                                                          : " p." + std::to_string(first) + "-" + std::to_string(last));
  };
  if (down <= kMapMaxRowEntries + 1) {
    for (int r = 0; r < down; ++r) bands.push_back(band(r));
  } else {  // shortened: the first ones, "...", the last one
    for (int r = 0; r < kMapMaxRowEntries - 1; ++r) bands.push_back(band(r));
    bands.push_back("...");
    bands.push_back(band(down - 1));
  }
  wrap("      ", bands, kMapRowsPerLine);
  return lines;
}

void set_rgb(cairo_t* cr, const Rgb& c) {
  cairo_set_source_rgb(cr, c.r / 255.0, c.g / 255.0, c.b / 255.0);
}

void draw_page(cairo_t* cr, const cv::Mat& grid, const ChartInfo& info, const Tile& t,
               int page, int pages, const std::vector<std::string>& map) {
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

  // Page map, on every page of a multi-page chart (so every page holds as many rows).
  cairo_set_source_rgb(cr, 0, 0, 0);
  for (size_t i = 0; i < map.size(); ++i)
    chart_text(cr, kMargin, kMargin + kHeader + (i + 0.7) * kMapLine, map[i], 7, i == 0);

  // Grid: top-left corner; the top row of the tile is row1, the leftmost column stitch1.
  const double gx = kMargin + kGutter, gy = kMargin + kHeader + map.size() * kMapLine;
  // The cells as one small image (a pixel per cell) scaled up without smoothing: one image
  // per page instead of a path of rectangles, so PDFs are small and fast to write.
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> cells(
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, ncols, nrows), cairo_surface_destroy);
  cairo_surface_flush(cells.get());
  {
    unsigned char* data = cairo_image_surface_get_data(cells.get());
    const int stride = cairo_image_surface_get_stride(cells.get());
    const uint32_t px[2] = {
        (uint32_t{info.colors[0].r} << 16) | (uint32_t{info.colors[0].g} << 8) | info.colors[0].b,
        (uint32_t{info.colors[1].r} << 16) | (uint32_t{info.colors[1].g} << 8) | info.colors[1].b};
    for (int r = 0; r < nrows; ++r) {
      int n = t.row1 - r;  // chart row, 1 = knitted first
      const unsigned char* line = grid.ptr<unsigned char>(info.first_row_top ? n - 1 : rows - n);
      auto* out = reinterpret_cast<uint32_t*>(data + static_cast<size_t>(r) * stride);
      for (int k = 0; k < ncols; ++k) out[k] = px[line[width - (t.stitch1 - k)] ? 1 : 0];  // stitch s at column width - s
    }
  }
  cairo_surface_mark_dirty(cells.get());
  cairo_save(cr);
  cairo_translate(cr, gx, gy);
  cairo_scale(cr, kCell, kCell);
  cairo_set_source_surface(cr, cells.get(), 0, 0);
  cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_NEAREST);
  cairo_rectangle(cr, 0, 0, ncols, nrows);
  cairo_fill(cr);
  cairo_restore(cr);
  // Grid lines: one path of thin lines and one of bold (every 10th) lines, bold on top.
  cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
  for (int pass = 0; pass < 2; ++pass) {
    const bool bold_pass = pass == 1;
    for (int k = 0; k <= ncols; ++k) {  // vertical line left of column k
      int s = t.stitch1 - k;  // the stitch right of this line
      if ((s % 10 == 0 && s > 0) != bold_pass) continue;
      cairo_move_to(cr, gx + k * kCell, gy);
      cairo_line_to(cr, gx + k * kCell, gy + nrows * kCell);
    }
    for (int r = 0; r <= nrows; ++r) {  // horizontal line below tile row r-1
      int below = t.row1 - r;           // the line separates rows below and below+1
      if ((below % 10 == 0 && below > 0) != bold_pass) continue;
      cairo_move_to(cr, gx, gy + r * kCell);
      cairo_line_to(cr, gx + ncols * kCell, gy + r * kCell);
    }
    cairo_set_line_width(cr, bold_pass ? 1.2 : 0.3);
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

std::vector<Tile> chart_tiles(const cv::Mat& grid) { return chart_layout(grid.cols, grid.rows); }

}  // namespace

std::vector<ChartTile> chart_layout(int stitches, int rows) {
  CV_Assert(stitches > 0 && rows > 0);
  const Layout l = make_layout(stitches, rows);
  std::vector<ChartTile> tiles;
  for (const auto& r : l.row_bands)
    for (const auto& s : l.stitch_bands) tiles.push_back(ChartTile{r.first, r.second, s.first, s.second});
  return tiles;
}

std::vector<std::string> chart_page_map(int stitches, int rows) {
  CV_Assert(stitches > 0 && rows > 0);
  return page_map_lines(make_layout(stitches, rows));
}

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
    draw_page(cr.get(), grid, info, tiles[static_cast<size_t>(page - 1)], page, static_cast<int>(tiles.size()),
              chart_page_map(grid.cols, grid.rows));
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
  const std::vector<std::string> map = chart_page_map(grid.cols, grid.rows);

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
                static_cast<int>(tiles.size()), map);
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
