#include "algorithms/parquetry/render.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace atelier::parquetry {
namespace {

constexpr int kShift = 4;  // sub-pixel bits for the polygon calls

std::vector<cv::Point> to_px(const std::vector<cv::Point2d>& mm, double s, cv::Point2d offset = {}) {
  std::vector<cv::Point> out;
  out.reserve(mm.size());
  for (const auto& p : mm) {
    out.emplace_back(static_cast<int>(std::lround((p.x * s - offset.x) * (1 << kShift))),
                     static_cast<int>(std::lround((p.y * s - offset.y) * (1 << kShift))));
  }
  return out;
}

}  // namespace

double render_px_per_mm(const Plan& plan, const RenderOptions& o) {
  const double longer = std::max({plan.width_mm, plan.height_mm, 1e-9});
  return std::max(1e-3, std::min(o.px_per_mm, o.max_px / longer));
}

cv::Mat render_plan(const Plan& plan, const std::vector<Sheet>& sheets, const RenderOptions& o) {
  const double s = render_px_per_mm(plan, o);
  const cv::Size size(std::max(1, static_cast<int>(std::lround(plan.width_mm * s))),
                      std::max(1, static_cast<int>(std::lround(plan.height_mm * s))));
  cv::Mat out(size, CV_8UC3, cv::Scalar::all(0));

  // Each used scan resampled once to the preview's scale (area averaging: no aliasing of the
  // grain when the scan is finer than the preview).
  std::map<std::string, cv::Mat> scaled;
  std::map<std::string, double> scan_px_per_mm;
  for (const Piece& piece : plan.pieces) {
    if (scaled.count(piece.sheet_id)) continue;
    auto it = std::find_if(sheets.begin(), sheets.end(), [&](const Sheet& sh) { return sh.id == piece.sheet_id; });
    if (it == sheets.end()) throw std::invalid_argument("render: no sheet '" + piece.sheet_id + "'");
    const double native = it->dpi / 25.4;
    if (native > s) {
      cv::Mat small;
      const cv::Size to(std::max(1, static_cast<int>(std::lround(it->image.cols * s / native))),
                        std::max(1, static_cast<int>(std::lround(it->image.rows * s / native))));
      cv::resize(it->image, small, to, 0, 0, cv::INTER_AREA);
      scaled[piece.sheet_id] = small;
      // The exact scale of the resampled scan, per axis averaged (they differ by rounding).
      scan_px_per_mm[piece.sheet_id] = native * 0.5 * (double(to.width) / it->image.cols +
                                                       double(to.height) / it->image.rows);
    } else {
      scaled[piece.sheet_id] = it->image;
      scan_px_per_mm[piece.sheet_id] = native;
    }
  }

  for (const Piece& piece : plan.pieces) {
    if (piece.target_mm.size() < 3) continue;
    std::vector<cv::Point> poly = to_px(piece.target_mm, s);
    cv::Rect box = cv::boundingRect(poly);
    box.x >>= kShift;
    box.y >>= kShift;
    box.width = (box.width >> kShift) + 3;
    box.height = (box.height >> kShift) + 3;
    box &= cv::Rect(cv::Point(0, 0), size);
    if (box.empty()) continue;
    // Output pixel (u, v) of the box -> result mm -> sheet mm -> scan px (pixel centres).
    const double k = scan_px_per_mm[piece.sheet_id];
    const cv::Matx23d& t = piece.to_sheet;
    cv::Matx23d m;
    for (int r = 0; r < 2; ++r) {
      m(r, 0) = k * t(r, 0) / s;
      m(r, 1) = k * t(r, 1) / s;
      const double cx = (box.x + 0.5) / s, cy = (box.y + 0.5) / s;
      m(r, 2) = k * (t(r, 0) * cx + t(r, 1) * cy + t(r, 2)) - 0.5;
    }
    cv::Mat patch;
    cv::warpAffine(scaled[piece.sheet_id], patch, cv::Mat(m), box.size(),
                   cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REPLICATE);
    cv::Mat mask(box.size(), CV_8UC1, cv::Scalar(0));
    const std::vector<std::vector<cv::Point>> local{to_px(piece.target_mm, s, cv::Point2d(box.x, box.y))};
    cv::fillPoly(mask, local, cv::Scalar(255), cv::LINE_8, kShift);
    patch.copyTo(out(box), mask);
  }

  const int joint = std::max(1, static_cast<int>(std::lround(o.joint_mm * s)));
  for (const Piece& piece : plan.pieces) {
    if (piece.target_mm.size() < 2) continue;
    const std::vector<std::vector<cv::Point>> poly{to_px(piece.target_mm, s)};
    cv::polylines(out, poly, true, o.joint_bgr, joint, cv::LINE_AA, kShift);
  }
  return out;
}

}  // namespace atelier::parquetry
