// Reference stitch textures (paper 5, Fig. 1a and 17a): one tile per stitch style with its
// colour, alpha (seams) and tangent-space normal map. The paper ships photographed tiles; we
// generate them procedurally (issue 6) and accept user tiles checked by validate_texture().
//
// Tile frame: u = tile x (column, left to right) = along the stitches for long-short and edge,
// across the column for satin; v = tile y (row, top to bottom) = along the row growth.
// Normal maps use the OpenGL convention in the tile frame: R = +u, G = -v (up in the picture),
// B = out of the fabric; (128,128,255) in R,G,B order is flat. Mats are OpenCV B,G,R order, so
// a flat normal pixel is cv::Vec3b(255,128,128).
// Value types; procedural_textures() is pure and deterministic; thread-safe.
#pragma once

#include <opencv2/core.hpp>

#include "algorithms/embroidery/design.h"

namespace atelier::embroidery {

// A reference texture of one stitch style: one stitch-texture tile (the paper's reference image).
struct ReferenceTexture {
  cv::Mat3b color;      // thread texture in its reference colour (any colour; recolouring maps it)
  cv::Mat1b alpha;      // 0 = seam (transparent), 255 = thread
  cv::Mat3b normal;     // tangent-space normal map, 8-bit, (128,128,255) = flat, same size
  double width_mm = 0, height_mm = 0;   // physical size of the tile (sets stitch length, paper 6)
};

struct TextureSet {
  ReferenceTexture style[kStyleCount];   // indexed by (int)Style
};

// Procedural textures that read as embroidery: parallel thread strands with twist shading,
// highlights and the seams between stitches. Deterministic. Sizes (32 tile pixels per mm):
//  - long-short: 8 mm (u, along the stitches) x 3 mm (v): ten 0.3 mm threads per row, stitch
//    length 4 mm with the stitch ends of neighbouring threads staggered by 2 mm (long and short
//    stitches). The centre u in [0.25, 0.75] is exactly one period, so repeating it is seamless;
//    the threads end cleanly at u = 0 and u = 1 (where the row meets the region contour).
//  - satin: 4 mm (u, across the column; stretched to the column width) x 1.2 mm (v, along the
//    column): three threads 0.4 mm apart (Ink/Stitch's zig-zag spacing), each one stitch across
//    the whole column, on a domed column with a sheen before its crest.
//  - edge: 2 mm (u, along the stroke) x 1 mm (v, across it): short stitches slanted at 35 deg,
//    0.33 mm apart, with small transparent gaps between them.
TextureSet procedural_textures();

// Checks a user texture: colour non-empty, alpha and normal of the same size, finite positive
// width_mm and height_mm. Throws std::invalid_argument naming the problem.
void validate_texture(const ReferenceTexture&);

}  // namespace atelier::embroidery
