// Hatching for sketch jobs (Meraj et al. 2008, section 6, figure 7): dark regions of an image
// filled with parallel straight lines, and a second, crossing layer where they are darker still.
// Each hatch line is returned as a Segment and drawn later as a human-like pencil line.
//
// Units: pixels of the input image, x right, y down; angles in degrees from +x towards +y (so
// clockwise on screen: 45 runs from top left to bottom right). Grey levels as fractions: 0 black
// .. 1 white. Pure function: no state, no I/O; deterministic; safe from any thread.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "algorithms/pencil/strokes.h"

namespace atelier::pencil {

struct HatchParams {
  double dark_level = 0.35;  // pixels darker than this (after smoothing) are hatched; [0, 1], 0 = none
  double cross_level = 0.15; // darker than this: a second, crossing layer; [0, dark_level], 0 = none
  double spacing_px = 6;     // between hatch lines; >= 1
  double angle_deg = 45;     // first layer's direction (the second is angle + 90); finite
  double min_length_px = 6;  // shorter hatch runs dropped; >= 0
  double min_area_px = 64;   // dark regions (8-connected) smaller than this are not hatched; >= 0
};

// The grey image (composited over white paper as on_white_paper does, converted to grey) is
// smoothed by a Gaussian of sigma spacing_px / 4 (detail finer than the spacing cannot show in
// hatching; the blur also keeps JPEG noise from fraying the regions), then thresholded: a pixel
// is dark if its grey level is below dark_level * 255, crossing if below cross_level * 255.
// Regions of fewer than min_area_px pixels are removed from each mask.
// Layer 1 lies on the lines {p : p . n = k * spacing_px}, k integer, n the unit normal of
// angle_deg (anchored at the image origin, so neighbouring regions' lines continue each other);
// each line is sampled every 0.25 px and every run of samples inside the mask (nearest pixel)
// gives one Segment from its first to its last inside sample -- so it is clipped to the region
// and ends within a pixel's half-diagonal of a mask pixel. Runs shorter than min_length_px are
// dropped. Layer 2 is the same at angle_deg + 90 on the crossing mask.
// Order, as a hand would hatch: layer 1, then layer 2; within a layer line by line (k
// ascending), each line in its direction.
// Throws std::invalid_argument for a bad image (see on_white_paper) or parameter (the message
// names it), std::runtime_error if OpenCV fails.
std::vector<Segment> hatch_lines(const cv::Mat& image, const HatchParams& params);

}  // namespace atelier::pencil
