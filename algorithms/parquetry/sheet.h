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

// Used wood per sheet id: CV_8UC1 masks (255 = used) at the working resolution, of the size
// sheet_size_px() gives. A sheet without an entry is unused. Plans read a Stock and return the
// updated one, so several jobs never plan the same wood twice.
struct Stock {
  double px_per_mm = 0;  // resolution of the masks; 0 = empty stock, any resolution
  std::map<std::string, cv::Mat> used;
};

// Size of a sheet's masks at `px_per_mm` (the scan resampled from dpi / 25.4 px per mm).
cv::Size sheet_size_px(const Sheet& sheet, double px_per_mm);

// Area in mm^2 of usable wood not yet used, over all sheets.
double free_area_mm2(const std::vector<Sheet>& sheets, const Stock& stock, double px_per_mm);

// Throws std::invalid_argument for an empty image, wrong types, a usable mask of another size,
// dpi <= 0 or a repeated id.
void validate_sheets(const std::vector<Sheet>& sheets);

}  // namespace atelier::parquetry
