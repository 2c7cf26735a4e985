// Travel between the pieces of one colour that the finished design hides (issue 21 point 6):
// running stitches through pixels that a later colour block covers (fill or satin, not an
// edge's running stitch) or that this block sews (thread of the same colour), as digitizers
// route travel instead of trimming.
// Units: the plan's millimetres in and out (origin at the design's centre, y down); the
// pixel grid of the segmentation inside. Not thread-safe (path() uses InsideTravel's scratch).
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "algorithms/embroidery/running_stitches.h"

namespace atelier::embroidery {

class HiddenTravel {
 public:
  // block_of_pixel: per design pixel the colour block that sews it, -1 for fabric; covers:
  // 255 where that thread covers the pixel (fill, satin), 0 where it does not (a running
  // stitch along an edge region). Both copied. cell_mm: the search grid (a cell must lie
  // wholly on hidden pixels).
  HiddenTravel(const cv::Mat1i& block_of_pixel, const cv::Mat1b& covers, double px_per_mm, double cell_mm);
  // From now on, pixels of `block` and covered pixels of later blocks hide travel.
  void begin_block(int block);
  // A hidden path from a to b (both included, mm), or false (none, or no block begun).
  // Bounded: a breadth-first search over the cells of the box around a and b grown by 10 mm
  // (or by half the move, when longer).
  bool path(cv::Point2d a_mm, cv::Point2d b_mm, std::vector<cv::Point2d>& out_mm) const;

 private:
  cv::Mat1i block_;
  cv::Mat1b covers_;
  double ppm_, cell_px_;
  cv::Point2d centre_;
  cv::Mat1b mask_;                        // hidden pixels of the current block
  std::unique_ptr<InsideTravel> travel_;  // over mask_
  mutable std::vector<cv::Point2f> scratch_;
};

}  // namespace atelier::embroidery
