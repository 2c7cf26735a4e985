#include "algorithms/parquetry/sheet.h"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <set>
#include <stdexcept>

#include "algorithms/laser/kerf.h"

namespace atelier::parquetry {

namespace {

// Half a pixel's diagonal: a polygon grown by this covers the centre of every pixel it touches.
constexpr double kPixelMargin = 0.7072;

}  // namespace

cv::Size sheet_size_px(const Sheet& sheet, double px_per_mm) {
  const double scale = px_per_mm * 25.4 / sheet.dpi;
  // A hair under the exact product, so a whole number of pixels is not lost to rounding.
  return {std::max(1, static_cast<int>(std::floor(sheet.image.cols * scale + 1e-9))),
          std::max(1, static_cast<int>(std::floor(sheet.image.rows * scale + 1e-9)))};
}

cv::Mat resample_sheet(const cv::Mat& image, const Sheet& sheet, double px_per_mm) {
  const double scale = px_per_mm * 25.4 / sheet.dpi;
  const cv::Size size = sheet_size_px(sheet, px_per_mm);
  // With no destination size, cv::resize uses the factors as given (the size only rounds);
  // with one it would stretch the scan to fit it. The rounded size is at least `size`; the
  // part beyond it (under a pixel, partly off the sheet) is cut off.
  cv::Mat out;
  cv::resize(image, out, cv::Size(), scale, scale, scale < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
  return out(cv::Rect(cv::Point(0, 0), size)).clone();
}

cv::Mat usable_mask(const Sheet& sheet, double px_per_mm) {
  const cv::Size size = sheet_size_px(sheet, px_per_mm);
  if (sheet.usable.empty()) return cv::Mat(size, CV_8UC1, cv::Scalar(255));
  return resample_sheet(sheet.usable, sheet, px_per_mm) > 250;
}

cv::Mat used_mask(const Sheet& sheet, const std::vector<UsedPiece>& used, double px_per_mm,
                  double kerf_mm) {
  cv::Mat mask = cv::Mat::zeros(sheet_size_px(sheet, px_per_mm), CV_8UC1);
  // Grown by the kerf and half a pixel diagonal (Clipper, round joins), then filled by pixel
  // centres: every pixel the kerf-grown piece touches is marked.
  const double grow = std::max(0.0, kerf_mm) * px_per_mm + kPixelMargin;
  constexpr int kShift = 8;
  for (const UsedPiece& piece : used) {
    if (piece.polygon_mm.size() < 3) continue;
    laser::Path path;
    path.closed = true;
    for (const cv::Point2d& p : piece.polygon_mm) {
      path.points.push_back({p.x * px_per_mm - 0.5, p.y * px_per_mm - 0.5});
    }
    const laser::KerfResult grown = laser::apply_kerf({path}, 2 * grow, 0.05);
    std::vector<std::vector<cv::Point>> polys;
    for (const laser::Path& g : grown.paths) {
      std::vector<cv::Point> poly;
      for (const laser::Point& q : g.points) {
        poly.emplace_back(static_cast<int>(std::lround(q.x * (1 << kShift))),
                          static_cast<int>(std::lround(q.y * (1 << kShift))));
      }
      polys.push_back(std::move(poly));
    }
    cv::fillPoly(mask, polys, cv::Scalar(255), cv::LINE_8, kShift);
  }
  return mask;
}

double used_area_mm2(const std::vector<UsedPiece>& used) {
  double a = 0;
  for (const UsedPiece& piece : used) {
    double s = 0;
    const auto& p = piece.polygon_mm;
    for (std::size_t i = 0; i < p.size(); ++i) s += p[i].cross(p[(i + 1) % p.size()]);
    a += std::abs(s) / 2;
  }
  return a;
}

double free_area_mm2(const std::vector<Sheet>& sheets, const Stock& stock, double px_per_mm,
                     double kerf_mm) {
  double px = 0;
  for (const Sheet& sheet : sheets) {
    cv::Mat free_wood = usable_mask(sheet, px_per_mm);
    if (auto it = stock.used.find(sheet.id); it != stock.used.end()) {
      free_wood &= ~used_mask(sheet, it->second, px_per_mm, kerf_mm);
    }
    px += cv::countNonZero(free_wood);
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
