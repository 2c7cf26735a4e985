// A realistic picture of what the machine will sew (issue 21 point 10), drawn from the stitch
// plan itself, not from the regions: every stitch is a thread of thread_width_mm between its
// two needle points, in its colour block's thread, shaded as a lit cylinder (darker flanks, a
// highlight towards the light, a faint twist at fine scales, a slight per-stitch variation),
// laid over the earlier stitches in sewing order and casting a soft shadow on the fabric.
// Jumps and trims are not drawn (the thread is cut); a stitch is drawn from the previous
// positioned point, so the first stitch after a jump starts where the jump ended.
//
// Frame: the preview's (synthesis.h). The plan's origin (0, 0) mm is the centre of the frame's
// pixel grid, ((w - 1) / 2, (h - 1) / 2), as plan_stitches() places it; x right, y down;
// px_per_mm pixels per mm. So stitches.png and preview.png overlay pixel for pixel.
// Units: mm in the plan and the parameters, pixels in the frame. Pure; deterministic (the
// result does not depend on the thread count); runs row bands in parallel with
// cv::parallel_for_; thread-safe.
#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

#include "algorithms/embroidery/stitch_plan.h"

namespace atelier::embroidery {

struct StitchRenderParams {
  cv::Size size;                        // the frame in pixels (the preview's)
  double px_per_mm = 4;                 // of the frame
  double thread_width_mm = 0.4;         // a 40 wt thread lies about 0.4 mm wide
  cv::Vec3b fabric_bgr{235, 235, 235};  // the synthesis' fabric colour, so both pictures match
  double variation = 0.06;              // per-stitch brightness spread (+-, fraction)
  std::uint32_t seed = 21;              // of the per-stitch variation
};

struct StitchRender {
  cv::Mat3b image;     // the frame: threads over the fabric
  cv::Mat1b coverage;  // thread coverage per pixel, 0 (bare fabric) .. 255 (all thread),
                       // antialiased: the area of the pixel the threads cover
  int stitches_drawn = 0;
};

// Throws std::invalid_argument when the size is empty, px_per_mm or thread_width_mm is not
// positive and finite, or a positioned point is not finite (validate_plan). Threads are drawn
// in colors_rgb[block] (block = colour changes so far); a block without a colour is grey.
StitchRender render_stitches(const StitchPlan& plan, const StitchRenderParams& params);

}  // namespace atelier::embroidery
