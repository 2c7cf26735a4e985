#include "algorithms/embroidery/pipeline.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "algorithms/embroidery/directions.h"

namespace atelier::embroidery {

double working_px_per_mm(int cols, const DesignParams& p) {
  return std::clamp(cols / p.width_mm, p.min_px_per_mm, p.max_px_per_mm);
}

Design make_design(const cv::Mat& image, const TextureSet& textures, const DesignParams& params) {
  if (image.empty()) throw std::invalid_argument("the image is empty");
  if (!(params.width_mm > 0)) throw std::invalid_argument("width_mm must be positive");
  if (!(params.min_px_per_mm > 0) || params.max_px_per_mm < params.min_px_per_mm)
    throw std::invalid_argument("the working resolution bounds are wrong");
  if (!(params.eW_mm > 0) || !(params.sW_mm > params.eW_mm))
    throw std::invalid_argument("sW must be wider than eW, and eW positive");

  Design d;
  d.px_per_mm = working_px_per_mm(image.cols, params);
  const double scale = d.px_per_mm * params.width_mm / image.cols;
  cv::Mat work = image;
  if (std::abs(scale - 1.0) > 1e-6) {
    const cv::Size size(std::max(1, static_cast<int>(std::lround(image.cols * scale))),
                        std::max(1, static_cast<int>(std::lround(image.rows * scale))));
    cv::resize(image, work, size, 0, 0, scale > 1 ? cv::INTER_CUBIC : cv::INTER_AREA);
  }
  d.work_size = work.size();
  d.width_mm = params.width_mm;
  d.height_mm = params.width_mm * work.rows / work.cols;
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
