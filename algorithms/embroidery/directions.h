// Stitch directions per region (paper 5.1): the rotation of each region's stitch x-axis.
// Units: radians in the image frame (x right, y down; positive angles turn x towards y),
// folded into [0, pi) because a stitch direction has no sign.
// Pure; deterministic; thread-safe. Runs over regions with cv::parallel_for_.
#pragma once

#include <vector>

#include "algorithms/embroidery/design.h"

namespace atelier::embroidery {

// Indexed like seg.regions. Satin and edge regions: the direction of their stitches averaged
// over the region (doubled-angle mean of the mask's boundary gradients: satin stitches run
// across the stroke, edge stitches along it). Long-short regions: the doubled-angle mean of
// the satin and edge neighbours met along the external contour, weighted by the contour length
// they share; with no such neighbour, the long axis of the minimum-area bounding box.
std::vector<double> region_directions(const Segmentation&);

// Doubled-angle mean helper: the axis whose doubled angle is the weighted mean of the doubled
// angles (axes, so 0 and pi are the same). Returns an angle in [0, pi).
double axis_mean(const std::vector<double>& angles, const std::vector<double>& weights);

}  // namespace atelier::embroidery
