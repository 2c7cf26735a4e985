#include "algorithms/embroidery/pipeline.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "algorithms/embroidery/directions.h"

namespace atelier::embroidery {

double design_width_mm(cv::Size size, const DesignParams& p) {
  if (p.width_mm > 0) return p.width_mm;
  const double w = p.stitches.hoop_width_mm - 2 * p.hoop_margin_mm;
  const double h = p.stitches.hoop_height_mm - 2 * p.hoop_margin_mm;
  if (!(w > 0) || !(h > 0)) throw std::invalid_argument("the hoop leaves no room inside its margin");
  return std::min(w, h * size.width / size.height);
}

double working_px_per_mm(cv::Size size, double width_mm, const DesignParams& p) {
  double ppm = std::clamp(size.width / width_mm, p.min_px_per_mm, p.max_px_per_mm);
  // A long thin strip at a large size must not ask for gigabytes: cap the pixel count.
  const double height_mm = width_mm * size.height / size.width;
  const double pixels = width_mm * height_mm * ppm * ppm;
  if (pixels > p.max_work_pixels) ppm *= std::sqrt(p.max_work_pixels / pixels);
  return ppm;
}

Design make_design(const cv::Mat& image, const TextureSet& textures, const DesignParams& params) {
  if (image.empty()) throw std::invalid_argument("the image is empty");
  if (!(params.width_mm >= 0)) throw std::invalid_argument("width_mm must not be negative");
  if (!(params.min_px_per_mm > 0) || params.max_px_per_mm < params.min_px_per_mm)
    throw std::invalid_argument("the working resolution bounds are wrong");
  if (!(params.eW_mm > 0) || !(params.sW_mm > params.eW_mm))
    throw std::invalid_argument("sW must be wider than eW, and eW positive");

  Design d;
  const double width_mm = design_width_mm(image.size(), params);
  const double height_mm = width_mm * image.rows / image.cols;
  // Nothing larger than the hoop can be sewn: say so before any work (and any memory).
  if (width_mm > params.stitches.hoop_width_mm || height_mm > params.stitches.hoop_height_mm) {
    char msg[160];
    std::snprintf(msg, sizeof msg, "design is %.1f x %.1f mm, the hoop is %.1f x %.1f mm", width_mm,
                  height_mm, params.stitches.hoop_width_mm, params.stitches.hoop_height_mm);
    throw HoopTooSmall(msg);
  }
  d.px_per_mm = working_px_per_mm(image.size(), width_mm, params);
  const double scale = d.px_per_mm * width_mm / image.cols;
  cv::Mat work = image;
  if (std::abs(scale - 1.0) > 1e-6) {
    const cv::Size size(std::max(1, static_cast<int>(std::lround(image.cols * scale))),
                        std::max(1, static_cast<int>(std::lround(image.rows * scale))));
    cv::resize(image, work, size, 0, 0, scale > 1 ? cv::INTER_CUBIC : cv::INTER_AREA);
  }
  d.work_size = work.size();
  d.width_mm = width_mm;
  d.height_mm = height_mm;
  const double px_mm = d.px_per_mm;

  ColorParams colors = params.colors;
  colors.min_area_px = std::max(1, static_cast<int>(std::lround(params.min_region_mm2 * px_mm * px_mm)));
  LabelParams labels = params.labels;
  labels.eW_px = params.eW_mm * px_mm;
  labels.sW_px = params.sW_mm * px_mm;
  d.segmentation = segment(work, colors, labels);
  d.directions = region_directions(d.segmentation);

  SynthesisParams synthesis = params.synthesis;
  synthesis.px_per_mm = px_mm;
  synthesis.dilate_px = static_cast<int>(std::lround(params.overlap_mm * px_mm));
  d.synthesis = synthesize(d.segmentation, d.directions, textures, synthesis);

  StitchParams stitches = params.stitches;
  stitches.px_per_mm = px_mm;
  d.plan = plan_stitches(d.segmentation, d.directions, stitches);
  return d;
}

}  // namespace atelier::embroidery
