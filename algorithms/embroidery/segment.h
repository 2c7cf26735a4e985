// Paper section 4, whole: an image becomes embroidery regions, each one colour and one stitch
// style. Colour extraction (colors.h), 4-connected single-colour components, the stroke width
// transform per component (swt.h), the n^0.8 rule, and the graph-cut stitch-style labelling
// (style_labels.h); regions are the 4-connected pieces of (component, style).
// Units: image pixels (eW_px, sW_px too: the caller converts from millimetres).
// Pure; thread-safe; internally parallel over components (cv::parallel_for_). Deterministic.
#pragma once

#include <opencv2/core.hpp>

#include "algorithms/embroidery/colors.h"
#include "algorithms/embroidery/design.h"
#include "algorithms/embroidery/style_labels.h"  // LabelParams

namespace atelier::embroidery {

// Input: CV_8UC3 BGR or CV_8UC4 BGRA (alpha < 128 = not sewn), not empty.
// Throws std::invalid_argument for an empty image, another type, or bad parameters (the
// message says which). The result is complete: palette (sewn colours only), color_index,
// component and region_id per pixel (-1 = not sewn, the same pixels in all three), regions
// with tight bounding boxes, bbox-sized masks and areas, and the counters. Regions are ordered
// by component, then style, then raster order; region masks tile the sewn pixels exactly.
Segmentation segment(const cv::Mat& image, const ColorParams& colors, const LabelParams& labels);

}  // namespace atelier::embroidery
