// The printable lace chart (issue 7: chart.svg and chart.pdf), drawn once with cairo for both.
//
// The standard lace chart: right-side rows only (wrong-side rows are purled and not drawn),
// row 1 at the bottom, read right to left; odd row numbers (1, 3, 5, ...) on the RIGHT edge;
// stitch numbers along the bottom counted from the right. Cell j from the right of chart row r
// is Chart::rows[r][j] (knitting order). Symbols: k = empty square, yo = circle, k2tog = "/",
// ssk = "\", s2kp = "^" with a vertical line (the centred double decrease), sk2p = an inverted V
// leaning left (its true lean; issue 22), grey = no stitch. Cells are
// laid out as lace charts are printed (algorithms/lace/chart_layout.h): every row has the same
// number of columns, each stitch sits over the stitches it is worked into, and grey "no
// stitch" cells fill the columns where a decrease is not yet balanced by a yarn-over (or the
// other way round), so the motif shows. At the top: a title line (title, multiple of N
// sts, rows) and a legend (symbol, abbreviation, "RS: ..." meaning), with a note on working a
// double yarn-over on the wrong side when the chart has one.
//
// SVG: one page of whatever size the chart needs, 6 mm cells; a <title> and <desc> (the
// legend as text) are added for readers and search, as cairo writes text as glyph outlines.
// PDF: A4 portrait; cells as large as fit one page up to 6 mm; when even 4 mm cells do not
// fit, 4 mm cells split over pages, bottom rows first, then right to left (the order they are
// knitted), each page naming the rows and stitches it covers.
//
// Thread-safe (surfaces are per call). The SVG and PDF are drawn into memory and written
// atomically (output_files.h); failures throw ConvertError naming the file. A chart that is
// not knittable from cast_on throws std::invalid_argument.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "algorithms/lace/chart.h"

namespace atelier {

struct LaceChartInfo {
  std::string title;  // e.g. the job's name; may be empty
};

void write_lace_chart_svg(const lace::Chart& chart, int cast_on, const LaceChartInfo& info,
                          const std::filesystem::path& svg);

// Returns the number of pages written (callers may ignore it).
int write_lace_chart_pdf(const lace::Chart& chart, int cast_on, const LaceChartInfo& info,
                         const std::filesystem::path& pdf);

// The SVG's page drawn into an image (for tests and previews): BGR, px_per_mm pixels per
// millimetre, white paper; cells[r][j] is the pixel rectangle of Chart::rows[r][j], grid[r][c]
// that of column c (counted from the right, chart_layout.h) of chart row r.
struct LaceChartRaster {
  cv::Mat image;  // CV_8UC3
  std::vector<std::vector<cv::Rect2d>> cells;
  std::vector<std::vector<cv::Rect2d>> grid;
};
LaceChartRaster render_lace_chart_png(const lace::Chart& chart, int cast_on,
                                      const LaceChartInfo& info, double px_per_mm = 8.0);

}  // namespace atelier
