// A parquetry plan (paper 3.2-3.4): the target photo rebuilt from veneer pieces, each matched
// to the unused wood it resembles most, on a regular grid, a morphed grid or with refined cuts.
//
// Coordinates. Result mm: origin at the result's top-left, x right, y down; the result is the
// target scaled so its shorter side is size_mm, then trimmed (centred) to whole patches.
// Sheet mm: see sheet.h. A piece is cut along `source` on its sheet and laid at `target`:
// source = to_sheet(target), a rigid motion (the piece turned by rotation_deg).
//
// Pure (no I/O, clocks or logging). make_plan uses OpenCV's worker threads (cv::parallel_for_)
// and is safe to call from several threads at once.
#pragma once

#include <opencv2/core.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "algorithms/parquetry/outline.h"
#include "algorithms/parquetry/params.h"
#include "algorithms/parquetry/sheet.h"
#include "base/error.h"

namespace atelier::parquetry {

// Tolerance of the flattened polygons below (mm).
inline constexpr double kFlattenMm = 0.05;

struct Piece {
  int id = 0;                 // 1..n in the order the pieces were matched (per plan)
  std::string sheet_id;
  double rotation_deg = 0;    // the wood turned by k * 360 / rotations, counter-clockwise on the scan
  Outline target;             // result mm
  Outline source;             // sheet mm: to_sheet applied to target
  cv::Matx23d to_sheet;       // result mm -> sheet mm (rotation + translation)
  std::vector<cv::Point2d> target_mm, source_mm;  // the outlines flattened within kFlattenMm
  double cost = 0;            // eq. 4: SSD of the weighted features at px_per_mm, per matched px
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
  int grid_cols = 0, grid_rows = 0;    // patches of the grid before splitting
  Grid grid = Grid::regular;
  Refine refine = Refine::none;
  std::vector<Piece> pieces;
  std::vector<SplitDecision> splits;
  cv::Mat reconstruction;    // CV_8UC3 BGR at px_per_mm: the wood laid out as planned
  cv::Mat target;            // CV_8UC3 BGR at px_per_mm: the trimmed target
  // Mean squared grey-level error (0..255 scale) against `target`:
  double error = 0;           // of the reconstruction
  // ... of the reconstruction with every piece flattened to its wood's mean colour: the
  // paper's figure-8 baseline; `error` below it is the detail the grain adds.
  double baseline_error = 0;
  // ... of every piece filled with the target's own mean colour there (the best a flat
  // colour per piece could do, outside the wood's gamut; for information).
  double target_mean_error = 0;
  // Blurred SSIM of the reconstruction against `target` (quality.h): 1 = identical.
  double ssim = 0;
  // Eq. 8 (summed squared feature differences) of the straight grid cuts and of the refined
  // cuts, refine = dp only (0 otherwise).
  double seam_cost_straight = 0, seam_cost_refined = 0;
  // refine = dp: seams (cuts between two crossings) left refined and put back straight because
  // they read worse (seam_choice.h), and whether the curves were cut at all (false: they read
  // worse than the straight grid, or could not be cut, so the plan is the regular one).
  int seams_refined = 0, seams_straightened = 0;
  bool curves_cut = false;
};

// Thrown when the wood left cannot hold the plan; says how much area was needed and free.
class OutOfWood : public BadInput {
 public:
  OutOfWood(const std::string& what, double needed_mm2, double free_mm2)
      : BadInput(what), needed_mm2(needed_mm2), free_mm2(free_mm2) {}
  double needed_mm2, free_mm2;
};

// Thrown when the shapes cannot be made fabricable (a piece below 5 mm, in several parts or
// with a sliver thinner than min_feature_mm); says which piece and why.
class Unfabricable : public BadInput {
 public:
  using BadInput::BadInput;
};

// `target` is CV_8UC3 BGR (or CV_8UC1 / CV_8UC4). Throws std::invalid_argument for bad
// parameters or sheets, OutOfWood when the wood runs out, Unfabricable.
Plan make_plan(const cv::Mat& target, const std::vector<Sheet>& sheets, const Stock& stock,
               const Params& params);

// Several targets planned together on the same wood (paper 4.2): the patches of all targets
// in one priority queue (saliency scores compared across targets, or centre distance), so
// the most salient patches of every target get the best wood. Plans in the targets' order.
std::vector<Plan> make_plans(const std::vector<cv::Mat>& targets,
                             const std::vector<Sheet>& sheets, const Stock& stock,
                             const Params& params);

// `stock` plus the pieces of `plan` (their source outlines), labelled with `job`.
Stock with_plan(Stock stock, const Plan& plan, const std::string& job);

}  // namespace atelier::parquetry
