#include "convert/embroidery/thread_sheet.h"

#include <cairo-pdf.h>
#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "convert/common/cairo_output.h"
#include "convert/common/chart_text.h"
#include "convert/common/output_files.h"

namespace atelier {
namespace emb = embroidery;

std::vector<ThreadBlock> thread_blocks(const emb::StitchPlan& plan) {
  std::vector<ThreadBlock> out(1);
  bool have_prev = false;
  double px = 0, py = 0;
  for (const emb::StitchPoint& p : plan.points) {
    if (p.kind == emb::StitchKind::end) break;
    if (p.kind == emb::StitchKind::color_change) out.emplace_back();
    if (!emb::is_positioned(p.kind)) continue;
    if (p.kind == emb::StitchKind::stitch) {
      ++out.back().stitches;
      if (have_prev) out.back().length_m += std::hypot(p.x_mm - px, p.y_mm - py) / 1000.0;
    }
    px = p.x_mm, py = p.y_mm, have_prev = true;
  }
  // A plan whose colours name more blocks than it changes to (or none at all) keeps its list.
  if (out.size() < plan.colors_rgb.size()) out.resize(plan.colors_rgb.size());
  for (size_t i = 0; i < out.size(); ++i) out[i].rgb = i < plan.colors_rgb.size() ? plan.colors_rgb[i] : 0x808080u;
  return out;
}

namespace {

constexpr double kMm = 72.0 / 25.4;   // points per millimetre
constexpr double kPageW = 210 * kMm, kPageH = 297 * kMm, kMargin = 15 * kMm;
constexpr double kRow = 9 * kMm;
constexpr double kPictureW = 180 * kMm, kPictureH = 105 * kMm;
constexpr int kMaxPicturePx = 900;    // ~200 dpi at the picture's largest printed size

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

std::string hex(std::uint32_t rgb) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%06x", rgb & 0xffffffu);
  return buf;
}

void rgb_source(cairo_t* cr, std::uint32_t rgb) {
  cairo_set_source_rgb(cr, ((rgb >> 16) & 0xff) / 255.0, ((rgb >> 8) & 0xff) / 255.0, (rgb & 0xff) / 255.0);
}

// Draws the picture into the box (x, y, w, h) keeping its aspect; returns its height drawn.
double draw_picture(cairo_t* cr, const cv::Mat3b& picture, double x, double y, double w, double h) {
  if (picture.empty()) return 0;
  cv::Mat3b img = picture;
  const int longest = std::max(img.cols, img.rows);
  if (longest > kMaxPicturePx) {
    const double f = static_cast<double>(kMaxPicturePx) / longest;
    cv::resize(picture, img, cv::Size(std::max(1, static_cast<int>(img.cols * f)), std::max(1, static_cast<int>(img.rows * f))),
               0, 0, cv::INTER_AREA);
  }
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surf(
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, img.cols, img.rows), cairo_surface_destroy);
  cairo_surface_flush(surf.get());
  unsigned char* data = cairo_image_surface_get_data(surf.get());
  const int stride = cairo_image_surface_get_stride(surf.get());
  if (!data) throw std::runtime_error("threads.pdf: cairo cannot hold the picture");
  for (int r = 0; r < img.rows; ++r) {
    auto* row = reinterpret_cast<std::uint32_t*>(data + static_cast<size_t>(r) * stride);
    for (int c = 0; c < img.cols; ++c) {
      const cv::Vec3b b = img(r, c);
      row[c] = (static_cast<std::uint32_t>(b[2]) << 16) | (static_cast<std::uint32_t>(b[1]) << 8) | b[0];
    }
  }
  cairo_surface_mark_dirty(surf.get());
  const double scale = std::min(w / img.cols, h / img.rows);
  const double dw = img.cols * scale, dh = img.rows * scale;
  const double ox = x + (w - dw) / 2;
  cairo_save(cr);
  cairo_translate(cr, ox, y);
  cairo_scale(cr, scale, scale);
  cairo_set_source_surface(cr, surf.get(), 0, 0);
  cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_GOOD);
  cairo_paint(cr);
  cairo_restore(cr);
  cairo_set_source_rgb(cr, 0.6, 0.6, 0.6);
  cairo_set_line_width(cr, 0.5);
  cairo_rectangle(cr, ox, y, dw, dh);
  cairo_stroke(cr);
  return dh;
}

// Column positions (points): stop number (right-aligned), swatch, RGB, thread, stitches and
// length (right-aligned).
constexpr double kStopX = 27 * kMm, kSwatchX = 32 * kMm, kRgbX = 50 * kMm, kThreadX = 75 * kMm,
                 kStitchesX = 160 * kMm, kLengthX = 192 * kMm;

void table_header(cairo_t* cr, double y) {
  cairo_set_source_rgb(cr, 0, 0, 0);
  chart_text(cr, kStopX, y, "stop", 9, true, 1.0);
  chart_text(cr, kSwatchX, y, "colour", 9, true);
  chart_text(cr, kRgbX, y, "RGB", 9, true);
  chart_text(cr, kThreadX, y, "thread", 9, true);
  chart_text(cr, kStitchesX, y, "stitches", 9, true, 1.0);
  chart_text(cr, kLengthX, y, "length (m)", 9, true, 1.0);
  cairo_set_line_width(cr, 0.8);
  cairo_move_to(cr, kMargin, y + 2.5 * kMm);
  cairo_line_to(cr, kPageW - kMargin, y + 2.5 * kMm);
  cairo_stroke(cr);
}

// One block's row; y is the text baseline.
void table_row(cairo_t* cr, double y, int number, const ThreadBlock& b) {
  cairo_set_source_rgb(cr, 0, 0, 0);
  chart_text(cr, kStopX, y, std::to_string(number), 11, true, 1.0);
  rgb_source(cr, b.rgb);
  cairo_rectangle(cr, kSwatchX, y - 5 * kMm, 14 * kMm, 6.5 * kMm);
  cairo_fill_preserve(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 0.5);
  cairo_stroke(cr);
  chart_text(cr, kRgbX, y, hex(b.rgb), 10, false);
  // A thread of two catalogues ("Brother ...\nJanome ...") takes two smaller lines.
  const std::size_t nl = b.thread.find('\n');
  if (b.thread.empty()) {
    chart_text(cr, kThreadX, y, "-", 10, false);
  } else if (nl == std::string::npos) {
    chart_text(cr, kThreadX, y, b.thread, 10, false);
  } else {
    chart_text(cr, kThreadX, y - 2.2 * kMm, b.thread.substr(0, nl), 8, false);
    chart_text(cr, kThreadX, y + 1.0 * kMm, b.thread.substr(nl + 1), 8, false);
  }
  chart_text(cr, kStitchesX, y, std::to_string(b.stitches), 10, false, 1.0);
  chart_text(cr, kLengthX, y, fmt("%.2f", b.length_m), 10, false, 1.0);
  cairo_set_source_rgb(cr, 0.8, 0.8, 0.8);
  cairo_set_line_width(cr, 0.3);
  cairo_move_to(cr, kMargin, y + 3 * kMm);
  cairo_line_to(cr, kPageW - kMargin, y + 3 * kMm);
  cairo_stroke(cr);
}

}  // namespace

std::string thread_sheet_pdf(const ThreadSheet& s) {
  CairoBytes bytes;
  cairo_surface_t* surface = cairo_pdf_surface_create_for_stream(CairoBytes::write, &bytes, kPageW, kPageH);
  cairo_t* cr = cairo_create(surface);
  int total_stitches = 0;
  double total_m = 0;
  for (const ThreadBlock& b : s.blocks) total_stitches += b.stitches, total_m += b.length_m;

  // Page 1: the design, its picture, then as many rows as fit; later pages: the rest.
  double y = kMargin + 6 * kMm;
  cairo_set_source_rgb(cr, 0, 0, 0);
  chart_text(cr, kMargin, y, "Thread sheet: " + s.design, 16, true);
  y += 7 * kMm;
  char line[200];
  std::snprintf(line, sizeof line, "%.1f x %.1f mm    %d stitches    %zu colour%s    %d trims    start: the design's centre",
                s.width_mm, s.height_mm, s.stitches, s.blocks.size(), s.blocks.size() == 1 ? "" : "s", s.trims);
  chart_text(cr, kMargin, y, line, 10, false);
  y += 5 * kMm;
  const double pic = draw_picture(cr, s.picture, kMargin, y, kPictureW, kPictureH);
  y += pic + (pic > 0 ? 10 * kMm : 4 * kMm);
  cairo_set_source_rgb(cr, 0, 0, 0);   // the picture's frame left grey
  chart_text(cr, kMargin, y, "Colour order", 12, true);
  y += 8 * kMm;
  table_header(cr, y);
  y += 10 * kMm;
  const double bottom = kPageH - kMargin - 2 * kRow;   // room for the totals and the note
  int page = 1;
  for (size_t i = 0; i < s.blocks.size(); ++i) {
    if (y > bottom) {
      cairo_show_page(cr);
      ++page;
      y = kMargin + 6 * kMm;
      cairo_set_source_rgb(cr, 0, 0, 0);
      chart_text(cr, kMargin, y, "Thread sheet: " + s.design + " (page " + std::to_string(page) + ")", 12, true);
      y += 10 * kMm;
      table_header(cr, y);
      y += 10 * kMm;
    }
    table_row(cr, y, static_cast<int>(i) + 1, s.blocks[i]);
    y += kRow;
  }
  cairo_set_source_rgb(cr, 0, 0, 0);
  chart_text(cr, kRgbX, y, "total", 10, true);
  chart_text(cr, kStitchesX, y, std::to_string(total_stitches), 10, true, 1.0);
  chart_text(cr, kLengthX, y, fmt("%.2f", total_m), 10, true, 1.0);
  y += 7 * kMm;
  chart_text(cr, kMargin, y,
             "Length: the stitches as sewn (top thread on the fabric); the thread through the fabric and at the "
             "trims comes on top.", 7.5, false);
  cairo_show_page(cr);
  cairo_destroy(cr);
  cairo_surface_finish(surface);
  const cairo_status_t st = cairo_surface_status(surface);
  cairo_surface_destroy(surface);
  if (st != CAIRO_STATUS_SUCCESS) throw std::runtime_error(std::string("threads.pdf: ") + cairo_status_to_string(st));
  return bytes.bytes;
}

void write_thread_sheet(const ThreadSheet& sheet, const std::filesystem::path& file) {
  write_output(file, thread_sheet_pdf(sheet));
}

}  // namespace atelier
