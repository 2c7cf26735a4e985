// The wood library: scanned veneer sheets and the stock of wood already used on them.
//
// Units: a sheet's scan is in pixels at `dpi`; sheet mm have their origin at the scan's
// top-left corner, x to the right, y down. Pure data, copyable; no I/O (the daemon loads and
// saves these).
#pragma once

#include <map>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace atelier::parquetry {

struct Sheet {
  std::string id;   // unique; names the sheet in plans and the stock
  cv::Mat image;    // CV_8UC3 BGR scan
  cv::Mat usable;   // CV_8UC1 at the scan's size, 255 = usable veneer; empty = all usable
  double dpi = 300;
};

// A piece of wood taken from a sheet: its outline in sheet mm, and who took it.
struct UsedPiece {
  std::string job;                      // the job that planned it ("" = unknown)
  int piece = 0;                        // the piece's id in that job's plan.json
  std::vector<cv::Point2d> polygon_mm;  // closed, first point not repeated
};

// Used wood per sheet id, as the pieces' outlines in sheet mm (resolution-free, so it survives
// a change of working resolution, and says which job used what). Plans read a Stock, and
// with_plan() adds a plan's pieces, so jobs never plan the same wood twice. Wood within
// kerf_mm of a used piece is not free (the kerf between two cuts).
struct Stock {
  std::map<std::string, std::vector<UsedPiece>> used;
};

// Size of a sheet's masks at `px_per_mm`: the scan resampled from dpi / 25.4 px per mm at
// exactly that scale, whole pixels only (floor), so pixel x spans [x, x + 1) / px_per_mm mm.
cv::Size sheet_size_px(const Sheet& sheet, double px_per_mm);

// `image` (the scan or its mask, the scan's size) resampled at exactly px_per_mm and cropped
// to sheet_size_px: INTER_AREA when shrinking, INTER_LINEAR when growing.
cv::Mat resample_sheet(const cv::Mat& image, const Sheet& sheet, double px_per_mm);

// Used-wood mask of one sheet: CV_8UC1 of sheet_size_px(sheet, px_per_mm), 255 on every
// pixel that a used piece, grown by kerf_mm, touches (conservative: a free pixel is free).
cv::Mat used_mask(const Sheet& sheet, const std::vector<UsedPiece>& used, double px_per_mm,
                  double kerf_mm);

// Usable mask of one sheet at px_per_mm (255 = veneer; conservative: every scan pixel under
// a working pixel must be usable).
cv::Mat usable_mask(const Sheet& sheet, double px_per_mm);

// Area in mm^2 of usable wood not yet used, over all sheets, and per sheet.
double free_area_mm2(const std::vector<Sheet>& sheets, const Stock& stock, double px_per_mm,
                     double kerf_mm = 0);
double used_area_mm2(const std::vector<UsedPiece>& used);  // sum of the polygons' areas

// Throws std::invalid_argument for an empty image, wrong types, a usable mask of another size,
// dpi <= 0 or a repeated id.
void validate_sheets(const std::vector<Sheet>& sheets);

}  // namespace atelier::parquetry
