// Hidden travel: InsideTravel over the pixels still to be sewn.
#include "algorithms/embroidery/travel.h"

#include <algorithm>
#include <cmath>

namespace atelier::embroidery {

HiddenTravel::HiddenTravel(const cv::Mat1i& block_of_pixel, const cv::Mat1b& covers, double px_per_mm,
                           double cell_mm)
    : block_(block_of_pixel.clone()),
      covers_(covers.clone()),
      ppm_(px_per_mm),
      cell_px_(std::max(2.0, cell_mm * px_per_mm)),
      centre_((block_of_pixel.cols - 1) / 2.0, (block_of_pixel.rows - 1) / 2.0) {}

void HiddenTravel::begin_block(int block) {
  travel_.reset();  // it refers to mask_
  cv::Mat1b later, own;
  cv::compare(block_, std::max(0, block) + 1, later, cv::CMP_GE);
  cv::compare(block_, block, own, cv::CMP_EQ);
  mask_ = (later & covers_) | own;
  travel_ = std::make_unique<InsideTravel>(mask_, cell_px_);
}

bool HiddenTravel::path(cv::Point2d a_mm, cv::Point2d b_mm, std::vector<cv::Point2d>& out_mm) const {
  out_mm.clear();
  if (!travel_) return false;
  auto px = [&](cv::Point2d p) { return cv::Point2f(static_cast<float>(p.x * ppm_ + centre_.x), static_cast<float>(p.y * ppm_ + centre_.y)); };
  const double margin_mm = std::max(10.0, cv::norm(b_mm - a_mm) / 2);
  const int margin_cells = static_cast<int>(std::ceil(margin_mm * ppm_ / cell_px_));
  if (!travel_->path(px(a_mm), px(b_mm), scratch_, margin_cells)) return false;
  out_mm.reserve(scratch_.size());
  for (const cv::Point2f& q : scratch_) out_mm.emplace_back((q.x - centre_.x) / ppm_, (q.y - centre_.y) / ppm_);
  // Exact ends: the search works in float pixels.
  out_mm.front() = a_mm;
  out_mm.back() = b_mm;
  return true;
}

}  // namespace atelier::embroidery
