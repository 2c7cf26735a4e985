// Internal to make_plan: the cells of a plan (regular squares, morphed quads, or enlarged
// windows whose cuts are refined after matching), matching each cell to wood, and the
// pieces' final outlines and fabricability.
//
// Units: working pixels of the result (origin top-left, pixel x spans [x, x + 1)). Not
// thread-safe (a WoodIndex is mutated); one plan at a time.
#pragma once

#include <vector>

#include "algorithms/parquetry/outline.h"
#include "algorithms/parquetry/plan.h"
#include "algorithms/parquetry/wood_index.h"

namespace atelier::parquetry {

// A cell matched to wood.
struct Placed {
  int cell = -1;        // grid cell (row * cols + col) it belongs to
  cv::Rect rect;        // the matched window in result px
  Match match;
  int level = 0;        // adaptive level
  Outline outline_px;   // the piece's outline in result px (inside rect)
  cv::Rect core;        // refine = dp: the core matched and taken (result px, inside rect)
};

struct Shapes {
  Grid grid = Grid::regular;
  Refine refine = Refine::none;
  int cols = 0, rows = 0, patch = 0;
  int half = 0;                                 // refine = dp: overlap reach beyond the core
  std::vector<cv::Rect> rects;                  // per cell: the window matched
  std::vector<Outline> outlines;                // per cell: the outline (morphed / regular)
  std::vector<cv::Mat> masks;                   // morphed: pixels of the cell inside its rect
  double wood_px = 0;                           // wood the cells need at least (px)
};

Shapes make_shapes(const cv::Mat& target, int cols, int rows, int patch, const Params& p);

// The pixels of `rect` (result px) whose centres `outline_px` covers: CV_8UC1 of its size,
// 255 inside.
cv::Mat piece_mask(const Outline& outline_px, const cv::Rect& rect);

// The core square of cell `cell` (result px).
cv::Rect cell_core(const Shapes& shapes, int cell);

// Matches cell `cell` (splitting it adaptively on the regular grid) and takes its wood;
// false when no free wood fits.
bool place_cell(const Shapes& shapes, int cell, const cv::Mat& f1, const cv::Mat& f2,
                WoodIndex& wood, const Params& p, std::vector<Placed>& placed,
                std::vector<SplitDecision>& splits);

struct SeamCosts {
  double straight = 0, refined = 0;   // eq. 8 of the straight and the dp cuts
  // As in Plan: seams left refined / put back straight (seam_choice.h), and whether the
  // curves are cut (false: not dp, or they read worse than the straight grid, or cannot be cut).
  int seams_refined = 0, seams_straightened = 0;
  bool curves_cut = false;
};

// refine = dp: the cuts in the overlaps (eq. 8-9), each seam kept only where it raises the
// blurred SSIM against `target` (CV_8UC3, seam_choice.h), the plan cut straight if the
// smoothed curves read worse than that; gives every placed cell its outline.
// `available[k]` (dp_wood.h) is the wood placed[k]'s cuts may use. Otherwise the outlines
// are already set and this returns zeros.
SeamCosts final_outlines(const Shapes& shapes, const cv::Mat& target, const cv::Mat& f1,
                         const cv::Mat& f2, const WoodIndex& wood,
                         const std::vector<cv::Mat>& available, const Params& p,
                         std::vector<Placed>& placed);

// Throws Unfabricable naming the first piece that cannot be cut or assembled.
void check_fabricable(const Plan& plan, const Shapes& shapes, const Params& p);

}  // namespace atelier::parquetry
