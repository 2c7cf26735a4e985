// Internal to refine = dp: which refined seams to keep. Eq. 9 minimises the feature error of
// the overlaps, which is not the picture a viewer sees; a seam is kept refined only where it
// raises the blurred SSIM of the reconstruction (quality.h), else cut straight.
//
// A seam is the part of a cut between two crossings: the rows of vertical cut i outside every
// horizontal band (and columns of horizontal cut j outside every vertical band), each run
// between two bands (or a band and the border). Straightened, it runs linearly between the cut's
// positions just outside it (level with the crossing where it meets the border, on its grid
// line if it meets none); the crossings themselves keep their refined positions.
//
// Units: working px of the result. Pure, deterministic, not thread-safe on `seams`.
#pragma once

#include <vector>

#include "algorithms/parquetry/cut_refine.h"

namespace atelier::parquetry {

struct SeamChoice {
  int kept = 0;          // seams left refined (moved off their straight line and better so)
  int straightened = 0;  // seams the refinement made worse, now straight
};

// `wood_bgr` per cell (row-major): the wood's colour over cell_window(in, c, r) (CV_8UC3);
// `target_bgr` the result's target (CV_8UC3, W x H). Decides every seam once, in order
// (vertical cuts, then horizontal), each against the state the earlier decisions left: exact,
// the SSIM difference computed on the seam's neighbourhood as far as the blur and the SSIM
// window reach.
SeamChoice choose_seams(Seams& seams, const SeamInput& in, const std::vector<cv::Mat>& wood_bgr,
                        const cv::Mat& target_bgr, double px_per_mm);

}  // namespace atelier::parquetry
