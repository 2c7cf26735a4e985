// The whole embroidery design of issue 6: an image -> regions with stitch styles (paper
// section 4, segment.h), the synthesized preview and normal map (section 5, synthesis.h) and
// the machine's stitches (stitch_planner.h), at the design's physical size.
//
// Size (paper 6): the design is width_mm wide; the image is worked on at px_per_mm =
// its width in pixels / width_mm, clamped to [min_px_per_mm, max_px_per_mm] by resizing it
// first (a small logo is enlarged so satin columns have pixels to measure; a large photo is
// reduced to 10 px/mm, the stitch files' 0.1 mm unit: finer detail cannot be sewn, a thread
// is 0.4 mm wide). The label widths eW
// and sW, the region dilation and the minimum region area are given in mm and converted here.
//
// Pure: no I/O, no clocks. Thread-safe (separate calls share nothing); uses OpenCV's threads.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "algorithms/embroidery/colors.h"
#include "algorithms/embroidery/design.h"
#include "algorithms/embroidery/segment.h"
#include "algorithms/embroidery/stitch_plan.h"
#include "algorithms/embroidery/stitch_planner.h"
#include "algorithms/embroidery/synthesis.h"
#include "algorithms/embroidery/textures.h"

namespace atelier::embroidery {

struct DesignParams {
  double width_mm = 0;               // the design's width; its height follows the image.
                                     // 0 = as large as fits the hoop with hoop_margin_mm
                                     // on every side
  double hoop_margin_mm = 5;         // room left for pull compensation and overlap
  double max_work_pixels = 16e6;     // the working image is reduced below this
  double min_px_per_mm = 4, max_px_per_mm = 10;   // working resolution bounds
  double min_region_mm2 = 1.0;       // smaller single-colour specks join a neighbour
  double eW_mm = 1.0, sW_mm = 6.0;   // the paper's eW and sW as physical widths
  double overlap_mm = 0.25;          // neighbouring regions are sewn this far into each other
  ColorParams colors;                // min_area_px is set from min_region_mm2
  LabelParams labels;                // eW_px and sW_px are set from the mm widths
  SynthesisParams synthesis;         // px_per_mm and dilate_px are set here
  StitchParams stitches;             // px_per_mm is set here
};

struct Design {
  double px_per_mm = 0;              // of the working image
  cv::Size work_size;                // the working image's size in pixels
  double width_mm = 0, height_mm = 0;
  Segmentation segmentation;
  std::vector<double> directions;    // per region, radians (directions.h)
  Synthesis synthesis;               // preview, normal map, UV, top style per pixel
  StitchPlan plan;                   // mm, origin at the design's centre
};

// Throws std::invalid_argument (empty image, bad parameters) and HoopTooSmall (also before
// any work when width_mm x its height is already larger than the hoop).
Design make_design(const cv::Mat& image, const TextureSet& textures, const DesignParams& params);

// The design's width in mm for an image of `size`: width_mm, or the fit to the hoop.
double design_width_mm(cv::Size size, const DesignParams& params);

// The working resolution make_design() uses for an image of `size` sewn `width_mm` wide.
double working_px_per_mm(cv::Size size, double width_mm, const DesignParams& params);

}  // namespace atelier::embroidery
