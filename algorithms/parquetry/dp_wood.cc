#include "algorithms/parquetry/dp_wood.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "algorithms/parquetry/sheet.h"

namespace atelier::parquetry {

namespace {

// The rect's corners (window px) on the sheet.
std::vector<cv::Point2d> on_sheet(const cv::Rect& r, const cv::Matx23d& to_sheet) {
  return {transformed(cv::Point2d(r.x, r.y), to_sheet), transformed(cv::Point2d(r.x + r.width, r.y), to_sheet),
          transformed(cv::Point2d(r.x + r.width, r.y + r.height), to_sheet),
          transformed(cv::Point2d(r.x, r.y + r.height), to_sheet)};
}

// Pixels of `labels` whose centre lies inside `polygon` (sheet px) set to `label`.
void fill_label(cv::Mat& labels, const std::vector<cv::Point2d>& polygon, int label) {
  constexpr int kShift = 8;
  std::vector<cv::Point> pts;
  for (const cv::Point2d& q : polygon) {
    pts.emplace_back(static_cast<int>(std::lround((q.x - 0.5) * (1 << kShift))),
                     static_cast<int>(std::lround((q.y - 0.5) * (1 << kShift))));
  }
  cv::fillPoly(labels, std::vector<std::vector<cv::Point>>{pts}, cv::Scalar(label), cv::LINE_8, kShift);
}

// Distance from p to the rectangle r (0 inside).
double distance_to(const cv::Rect& r, cv::Point2d p) {
  const double dx = std::max({r.x - p.x, 0.0, p.x - (r.x + r.width)});
  const double dy = std::max({r.y - p.y, 0.0, p.y - (r.y + r.height)});
  return std::hypot(dx, dy);
}

}  // namespace

std::vector<cv::Mat> available_wood(const std::vector<const Placed*>& placed,
                                    const std::vector<Sheet>& sheets, const Stock& stock,
                                    const WoodIndex& wood, double px_per_mm, double kerf_mm) {
  const double kerf_px = std::max(0.0, kerf_mm) * px_per_mm;
  // An outline may cover up to half a pixel beyond the centres it covers, and a pixel centre
  // maps onto the sheet within a pixel of its wood: rules keep 2 px to spare.
  const double clear_of_cores = kerf_px + 2.2;
  const double gap = kerf_px + 2.0;
  // Per sheet: free wood, and every core of the plan labelled by its index + 1.
  std::vector<cv::Mat> free_wood(sheets.size()), cores(sheets.size());
  for (std::size_t s = 0; s < sheets.size(); ++s) {
    free_wood[s] = usable_mask(sheets[s], px_per_mm);
    const auto it = stock.used.find(sheets[s].id);
    if (it != stock.used.end()) free_wood[s] &= ~used_mask(sheets[s], it->second, px_per_mm, kerf_mm);
    // A pixel away from the veneer's edge and from used wood (off the sheet is not free).
    cv::erode(free_wood[s], free_wood[s], cv::Mat(), {-1, -1}, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
    cores[s] = cv::Mat::zeros(free_wood[s].size(), CV_32S);
  }
  for (std::size_t k = 0; k < placed.size(); ++k) {
    const Placed& pl = *placed[k];
    const cv::Rect core_in_window(pl.core.tl() - pl.rect.tl(), pl.core.size());
    fill_label(cores[pl.match.sheet], on_sheet(core_in_window, wood.window_to_sheet(pl.match)),
               static_cast<int>(k) + 1);
  }

  std::vector<cv::Mat> out;
  for (std::size_t k = 0; k < placed.size(); ++k) {
    const Placed& pl = *placed[k];
    const int s = pl.match.sheet;
    const cv::Matx23d to_sheet = wood.window_to_sheet(pl.match);
    const cv::Rect core(pl.core.tl() - pl.rect.tl(), pl.core.size());  // in window px
    // Distances to the other cores, over the window's bounding box on the sheet grown by as
    // far as a rule can look.
    const cv::Rect sheet_rect(0, 0, cores[s].cols, cores[s].rows);
    std::vector<cv::Point2f> corners;
    for (const cv::Point2d& q : on_sheet(cv::Rect({0, 0}, pl.rect.size()), to_sheet)) corners.emplace_back(q);
    const cv::Rect bbox = cv::boundingRect(corners);
    const int reach = static_cast<int>(std::ceil(std::hypot(pl.rect.width, pl.rect.height) + clear_of_cores + gap)) + 2;
    const cv::Rect roi = cv::Rect(bbox.x - reach, bbox.y - reach, bbox.width + 2 * reach,
                                  bbox.height + 2 * reach) & sheet_rect;
    cv::Mat avail = cv::Mat::zeros(pl.rect.size(), CV_8UC1);
    avail(core).setTo(255);
    if (roi.area() > 0) {
      const cv::Mat labels = cores[s](roi);
      const cv::Mat not_other = (labels == 0) | (labels == static_cast<int>(k) + 1);
      cv::Mat to_other;  // distance (px) to the nearest pixel of another core
      cv::distanceTransform(not_other, to_other, cv::DIST_L2, cv::DIST_MASK_PRECISE);
      for (int y = 0; y < avail.rows; ++y) {
        for (int x = 0; x < avail.cols; ++x) {
          const cv::Point2d centre(x + 0.5, y + 0.5);
          if (core.contains({x, y})) continue;
          const cv::Point2d q = transformed(centre, to_sheet);
          const int sx = static_cast<int>(std::floor(q.x)), sy = static_cast<int>(std::floor(q.y));
          if (!roi.contains({sx, sy}) || !free_wood[s].at<uchar>(sy, sx)) continue;
          const double other = to_other.at<float>(sy - roi.y, sx - roi.x);
          if (other >= clear_of_cores && distance_to(core, centre) + gap <= other) avail.at<uchar>(y, x) = 255;
        }
      }
    }
    out.push_back(avail);
  }
  return out;
}

}  // namespace atelier::parquetry
