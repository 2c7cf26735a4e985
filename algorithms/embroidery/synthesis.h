// Stitch-style-based texture synthesis of a whole design (paper 5): every region is filled
// with its style's recoloured reference tile through a UV map (uv_long_short.h, uv_satin.h,
// uv_edge.h), regions are layered (5.5: long-short in the background, then satin, then edge on
// top), dilated so neighbours overlap, and composed through the tiles' alpha so seams show what
// lies below. The normal map is synthesized from the tiles' normal maps with the same UVs,
// turned into the image frame by the local stitch direction.
// Units: image pixels; texture tiles are scaled by px_per_mm (paper 6: pixel sizes over actual
// sizes). Pure; deterministic; runs regions in parallel with cv::parallel_for_ and is safe to
// call from several threads.
#pragma once

#include <vector>

#include "algorithms/embroidery/design.h"
#include "algorithms/embroidery/textures.h"

namespace atelier::embroidery {

struct SynthesisParams {
  double px_per_mm = 4;        // image pixels per design millimetre (texture tiles are scaled by it)
  double max_L = 85;           // recolouring caps the target L (paper 5.4)
  int dilate_px = 1;           // regions are dilated so neighbours overlap (5.5)
  cv::Vec3b fabric_bgr{235, 235, 235};   // what shows where nothing is sewn
};

struct Synthesis {
  cv::Mat3b preview;   // image size: the embroidery as it will look
  cv::Mat3b normal;    // image size: tangent-space normal map, OpenGL convention in the image
                       // frame (R = right, G = up, B = out); flat fabric = (128,128,255) in RGB
                       // order, stored B,G,R so cv::imwrite writes it right
  cv::Mat2f uv;        // image size: the UV value image (paper Fig. 2d), NaN where not sewn
  cv::Mat1b style;     // image size: (int)Style + 1 of the top layer, 0 = not sewn
};

// directions: region_directions(seg) (radians, indexed like seg.regions). Throws
// std::invalid_argument on a malformed input (sizes disagree, a bad texture, px_per_mm <= 0,
// max_L outside (0, 100], dilate_px < 0); std::runtime_error when OpenCV fails inside.
Synthesis synthesize(const Segmentation&, const std::vector<double>& directions, const TextureSet&,
                     const SynthesisParams&);

}  // namespace atelier::embroidery
