// Printable Fair-Isle chart (PDF via cairo) for hand and machine knitters.
//
// A4 portrait, 4.5 mm cells, split over as many pages as needed, the stitches and rows spread
// evenly over them (page widths and heights differ by at most one cell); each page says which
// rows and stitches it covers, and a multi-page chart carries a page map (which page holds
// which stitch and row range) under the header of every page, the first included. Row 1, drawn at the bottom, is the first row knitted: the bottom row
// of the picture (the chart is the picture upright), or with first_row_top its top row (the
// chart is the picture upside down, as the fabric comes off the machine; the header says so);
// right-side (odd) row numbers stand on the right edge, wrong-side (even) ones on the left,
// as a knitter reads them. Stitches are numbered along the bottom from the right. Every 10th
// grid line is bold. The first lines give the file name, size, max float and solver, and a
// colour key. Pages run bottom-up, then right to left: the order in which rows are knitted.
//
// Thread-safe (cairo surfaces are per call). The PDF is drawn into memory and written
// atomically (output_files.h); throws ConvertError naming the file when it cannot be.
#pragma once

#include <array>
#include <filesystem>
#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "convert/knit/knit_params.h"

namespace atelier {

struct ChartInfo {
  std::string title;            // usually the input's file name
  int max_float = 4;
  std::string solver;
  std::array<Rgb, 2> colors{};  // background, contrast
  std::array<std::string, 2> color_names{};  // "#rrggbb" as configured
  bool first_row_top = false;  // [knit] first_row = "top": grid row 0 is row 1 (knitted first)
  std::function<void(double)> progress;      // fraction of pages written; may be empty
};

// One page's share of the chart: pattern rows (1 = knitted first) and stitches (counted from
// the right), inclusive.
struct ChartTile {
  int row0, row1;
  int stitch0, stitch1;
};

// The pages of a `stitches` x `rows` chart in the order they are knitted (bottom rows first,
// then right to left): as few pages as fit, columns and rows split evenly. Pure.
std::vector<ChartTile> chart_layout(int stitches, int rows);

// The page map's text lines for that layout (empty for a one-page chart): the stitch range of
// each page column and the row range (and pages) of each page row. At most a few lines for
// any size (long lists are shortened with "..."). Pure.
std::vector<std::string> chart_page_map(int stitches, int rows);

// `grid`: CV_8UC1, 1 = contrast, row 0 = top of the picture. Returns the number of pages.
int write_chart_pdf(const cv::Mat& grid, const ChartInfo& info, const std::filesystem::path& pdf);

// Page `page` (1-based, at most the page count) of the same chart drawn by the same code into
// a white BGR image, `px_per_mm` pixels per millimetre: for looking at a chart (and testing
// what is drawn) without a PDF reader. std::out_of_range for a page the chart does not have.
cv::Mat render_chart_page(const cv::Mat& grid, const ChartInfo& info, int page, double px_per_mm);

}  // namespace atelier
