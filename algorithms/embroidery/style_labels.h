// Paper section 4, eq. 1-6: the stitch-style labelling of one single-colour component as a
// multi-label energy (data costs on the contour pixels with a valid stroke width, smooth costs
// between 4-neighbours and between each pixel and its nearest such contour pixel, label costs),
// minimised by alpha-expansion with label costs (alpha_expansion.h).
// Units: widths in image pixels; costs are dimensionless. Pure; thread-safe.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "algorithms/embroidery/alpha_expansion.h"
#include "algorithms/embroidery/design.h"
#include "algorithms/embroidery/swt.h"

namespace atelier::embroidery {

struct LabelParams {
  double eW_px = 4, sW_px = 24;   // the paper's eW and sW (desired edge and satin widths), px
  double k1 = 10, k2 = 10;        // data cost weights (eq. 1-3)
  double k3 = 4, k4 = 2;          // smooth cost: a change to or from edge / between the others
  // Label costs c_LS, c_ST, c_ES (eq. 6), indexed by Style. Satin is the highest: at widths near
  // sW its data cost cannot tell it from long-short, and long-short fits irregular shapes.
  double label_cost[kStyleCount] = {20, 120, 60};
  // Speed: a component with more pixels is labelled on square blocks of pixels (one label per
  // block, the block side chosen so about this many blocks remain); >= 16.
  int max_cut_nodes = 2000;
};

// Throws std::invalid_argument naming the bad parameter: eW_px, sW_px, k1..k4 and label costs
// must be finite, eW_px > 0, sW_px > eW_px, k >= 0, label costs >= 0.
void validate_label_params(const LabelParams& p);

// Eq. 1-3: the data cost of `style` at a contour pixel whose stroke width is width_px.
double data_cost(Style style, double width_px, const LabelParams& p);
// Eq. 5 (a metric on the styles, as alpha-expansion needs).
double smooth_cost(Style a, Style b, const LabelParams& p);

// The labelling problem of one component. Node n is the n-th mask pixel in raster order.
struct StyleProblem {
  LabelProblem problem;            // labels are Style values
  std::vector<cv::Point> pixels;   // node -> mask coordinates
  cv::Mat1i node;                  // mask size: node index, -1 outside the component
};

// mask: the component on its bounding box (non-zero inside); widths: stroke_widths() of it.
StyleProblem style_problem(const cv::Mat1b& mask, const StrokeWidths& widths, const LabelParams& p);

struct StyleSolution {
  std::vector<int> labels;   // per node, Style values
  double energy = 0;         // labelling_energy of `labels`
  double single_energy = 0;  // the best single-label energy
  Style single = Style::long_short;
  bool graph_cut = false;    // false when the best single label was provably optimal
};

// Starts from the best single label. When that labelling's energy already equals the lower
// bound sum(min data cost) + min(label cost), it is a global optimum and no cut is needed;
// otherwise alpha-expansion runs. energy <= single_energy always.
StyleSolution solve_styles(const LabelProblem& problem);

// solve_styles on sp, on blocks of pixels when sp has more than max_cut_nodes nodes (see
// LabelParams::max_cut_nodes). labels, energy and single_energy refer to sp.problem.
StyleSolution solve_styles(const StyleProblem& sp, int max_cut_nodes);

// Labels one component end to end: the mask-sized style map (Style values, 255 outside the
// component). Components whose SWT failures exceed n^0.8 are long-short (*forced = true).
// Labelled islands under min_area_px pixels take the style they share the most border with.
cv::Mat1b label_component(const cv::Mat1b& mask, cv::Point origin, cv::Size image,
                          const LabelParams& p, int min_area_px, bool* forced = nullptr);

}  // namespace atelier::embroidery
