#include "algorithms/parquetry/sheet.h"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <set>
#include <stdexcept>

namespace atelier::parquetry {

cv::Size sheet_size_px(const Sheet& sheet, double px_per_mm) {
  const double scale = px_per_mm * 25.4 / sheet.dpi;
  return {std::max(1, static_cast<int>(std::lround(sheet.image.cols * scale))),
          std::max(1, static_cast<int>(std::lround(sheet.image.rows * scale)))};
}

double free_area_mm2(const std::vector<Sheet>& sheets, const Stock& stock, double px_per_mm) {
  double px = 0;
  for (const Sheet& sheet : sheets) {
    const cv::Size size = sheet_size_px(sheet, px_per_mm);
    cv::Mat usable(size, CV_8UC1, cv::Scalar(255));
    if (!sheet.usable.empty()) {
      cv::resize(sheet.usable, usable, size, 0, 0, cv::INTER_AREA);
      usable = usable > 250;
    }
    if (auto it = stock.used.find(sheet.id); it != stock.used.end() && !it->second.empty() &&
                                              it->second.size() == size) {
      usable &= ~(it->second > 0);
    }
    px += cv::countNonZero(usable);
  }
  return px / (px_per_mm * px_per_mm);
}

void validate_sheets(const std::vector<Sheet>& sheets) {
  std::set<std::string> ids;
  for (const Sheet& s : sheets) {
    const std::string name = "parquetry: sheet '" + s.id + "': ";
    if (s.id.empty()) throw std::invalid_argument("parquetry: a sheet has no id");
    if (!ids.insert(s.id).second) throw std::invalid_argument(name + "id used twice");
    if (s.image.empty() || s.image.type() != CV_8UC3) {
      throw std::invalid_argument(name + "image must be a non-empty 8-bit BGR image");
    }
    if (!s.usable.empty() && (s.usable.type() != CV_8UC1 || s.usable.size() != s.image.size())) {
      throw std::invalid_argument(name + "usable mask must be 8-bit grey of the image's size");
    }
    if (!(s.dpi > 0)) throw std::invalid_argument(name + "dpi must be positive");
  }
}

}  // namespace atelier::parquetry
