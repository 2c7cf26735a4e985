// Internal helper for the knit library: validation and row access shared by the float
// checker and the solvers. Pure, no state.
#pragma once

#include <opencv2/core.hpp>

#include "algorithms/knit/floats.h"
#include "algorithms/knit/row_runs.h"

namespace atelier::knit::detail {

// Throws std::invalid_argument unless `grid` is a non-empty CV_8UC1 grid of 0/1 values,
// rules.max_float >= 2 and the relax mask is empty or a CV_8UC1 of the grid's size.
// `who` names the caller in the message.
void check_problem(const cv::Mat& grid, const FloatRules& rules, const char* who);

// Row `y` of a checked problem. The grid is not modified through a const grid's view.
inline RowView row_view(const cv::Mat& grid, const FloatRules& rules, int y) {
  return RowView{const_cast<uint8_t*>(grid.ptr<uint8_t>(y)),
                 rules.relax.empty() ? nullptr : rules.relax.ptr<uint8_t>(y), grid.cols,
                 rules.max_float, rules.anchoring};
}

}  // namespace atelier::knit::detail
