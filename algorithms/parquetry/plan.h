// A parquetry plan (paper 3.2-3.3): the target photo rebuilt from square veneer patches on a
// regular grid, each matched to the unused wood it resembles most.
//
// Coordinates. Result mm: origin at the result's top-left, x right, y down; the result is the
// target scaled so its shorter side is size_mm, then trimmed (centred) to whole patches.
// Sheet mm: see sheet.h. A piece is cut along `source_mm` on its sheet, turned by
// `rotation_deg` counter-clockwise as seen on the scan (y down), and laid at `target_mm`;
// source_mm[i] lands on target_mm[i] (corners top-left, top-right, bottom-right, bottom-left
// of the target square).
//
// Pure (no I/O, clocks or logging). make_plan uses OpenCV's worker threads (cv::parallel_for_)
// and is safe to call from several threads at once.
#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "algorithms/parquetry/params.h"
#include "algorithms/parquetry/sheet.h"

namespace atelier::parquetry {

struct Piece {
  int id = 0;                 // 1..n in the order the pieces were matched
  std::string sheet_id;
  double rotation_deg = 0;    // k * 360 / rotations
  std::array<cv::Point2d, 4> source_mm;
  std::array<cv::Point2d, 4> target_mm;
  double cost = 0;            // eq. 4: SSD of the weighted features at px_per_mm
  int level = 0;              // 0 = full patch, 1 = a quarter, ...
};

// One adaptive decision (paper 3.3): a patch matched whole, and its four quarters.
struct SplitDecision {
  cv::Rect2d target_mm;
  double whole_cost = 0;
  double quarters_cost = 0;   // sum over the four quarters (each possibly split further)
  bool split = false;         // quarters_cost < adaptive_factor * whole_cost
};

struct Plan {
  double width_mm = 0, height_mm = 0;  // the result
  int grid_cols = 0, grid_rows = 0;    // patches of the regular grid before splitting
  std::vector<Piece> pieces;
  std::vector<SplitDecision> splits;
  cv::Mat reconstruction;    // CV_8UC3 BGR at px_per_mm: the wood laid out as planned
  cv::Mat target;            // CV_8UC3 BGR at px_per_mm: the trimmed target
  // Mean squared grey-level error (0..255 scale) against the target `target`:
  double error = 0;           // of the reconstruction
  double baseline_error = 0;  // of every patch filled with the target's mean colour there
  // ... and of the reconstruction with every wood patch flattened to its own mean colour (the
  // paper's figure-8 baseline): `error` below this is detail the grain adds. Note the
  // reconstruction is in the wood's gamut (eq. 2 pulls the target towards it by w_hist), so at
  // w_hist > 0 `error` also pays for the gamut change that baseline_error does not.
  double wood_mean_error = 0;
  Stock stock;               // the input stock plus the wood this plan uses
};

// Thrown when the wood left cannot hold the plan; says how much area was needed and free.
class OutOfWood : public std::runtime_error {
 public:
  OutOfWood(const std::string& what, double needed_mm2, double free_mm2)
      : std::runtime_error(what), needed_mm2(needed_mm2), free_mm2(free_mm2) {}
  double needed_mm2, free_mm2;
};

// `target` is CV_8UC3 BGR (or CV_8UC1). Throws std::invalid_argument for bad parameters,
// sheets or a stock at another resolution, OutOfWood when the wood runs out.
Plan make_plan(const cv::Mat& target, const std::vector<Sheet>& sheets, const Stock& stock,
               const Params& params);

}  // namespace atelier::parquetry
