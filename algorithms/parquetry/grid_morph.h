// A-priori grid morphing (paper 3.4, eq. 5-7): the regular patch grid bent so that its lines
// follow the large edges of the target, while every cell stays cuttable.
//
// Units: pixels of the target at working resolution; continuous coordinates with the origin at
// the top-left corner of the target (pixel (i, j) covers [i, i+1) x [j, j+1)), y down.
// Pure (no I/O, clocks or logging), deterministic, thread-safe; nothing is retained.
//
// Differences from the paper, on purpose:
// - No user-editable masks (a daemon has no user at the screen): M_RG = 1 everywhere and
//   M_bilateral = 1 only on fine edges at least one pitch long (shorter ones are texture the
//   wood's grain renders, not patch shape), 0 elsewhere; `fine_edges = false` sets it to 0.
// - Eq. 6's tent attracts a vertex only where D(E) < r / 2 and pushes it away where
//   r / 2 < D(E) < r. The paper wants the edges to attract within half the grid spacing, so
//   morph_grid uses r = 2 * (half the spacing) = one pitch by default (`radius_pitches`).
// - Cell edges stay the straight segments between vertices here; the paper's diagonal split
//   of a cell into two triangles where an image edge runs across it is left out (every cell
//   stays a quad). curved_grid.h rounds the lines into G1 curves.
#pragma once

#include <opencv2/core.hpp>

#include "algorithms/parquetry/curved_grid.h"

namespace atelier::parquetry {

// Eq. 5: the edges the grid should follow, CV_8UC1 (0 / 255) of the target's size.
// E_RG: rolling guidance filter (Zhang et al. 2014: a Gaussian, then 4 joint bilateral
// iterations, sigma_space = pitch / 3, so structures smaller than about a patch vanish; run at
// a scale of about 12 px per pitch) + Canny; E_bilateral: bilateral filter + Canny, kept where a chain of edge
// pixels is at least one pitch long (the automatic M_bilateral; dropped when !fine_edges).
// E = max(E_RG, M_bilateral o E_bilateral). `target` is CV_8UC3 BGR (CV_8UC1 / CV_8UC4 also
// accepted); pitch_px > 0. Throws std::invalid_argument on bad input.
cv::Mat morph_edges(const cv::Mat& target, double pitch_px, bool fine_edges = true);

// Eq. 6: P = max(0, min(D(E), r - D(E))), D the Euclidean distance (px) from each pixel to the
// nearest non-zero pixel of `edges` (CV_8UC1). CV_32F of the edges' size, in px; all zero when
// there is no edge. radius_px > 0.
cv::Mat edge_potential(const cv::Mat& edges, double radius_px);

// Eq. 7 and the solver. Lengths are in pitches and time in steps of the solver, so the same
// settings behave the same at any resolution. Each vertex has unit inertia and feels
//   F = spring * sum_j (|x_j - x_i| - L_ij) (x_j - x_i) / |x_j - x_i|   (8 neighbours,
//       L_ij the regular grid's 1 or sqrt 2)
//     - damping * v - edge_weight * grad P,
// where grad P is taken of P smoothed by a Gaussian of 1/16 pitch (at least 1 px), so the pull
// is smooth at the scale of a pixel-thin edge and stays a gradient (the mesh settles).
struct MorphSettings {
  // The paper's m ("mass"), which in eq. 7 scales the spring term: a stiffness per pitch.
  double spring = 1.0;
  // gamma: below critical for the stiff pull at an edge, above it for the slow whole-grid
  // modes; the fruits photo settles (no vertex moving 1e-6 pitch per step) in about 250 steps.
  double damping = 2.0;
  // w: 3 beats the 8 springs (about 4 * spring per pitch of displacement) anywhere in the
  // attraction zone, so a vertex within half a pitch of an edge reaches it.
  double edge_weight = 3.0;
  // Semi-implicit (symplectic) Euler step; stable well beyond the stiffest term at 0.1.
  double time_step = 0.1;
  // Upper bound on steps; the solver stops earlier once no vertex moves more than 1e-6 pitch.
  int iterations = 3000;
  // r of eq. 6 in pitches (see the note at the top: attraction within r / 2).
  double radius_pitches = 1.0;
  // "Convex enough": every interior angle within [min_angle_deg, 180 - min_angle_deg].
  double min_angle_deg = 30.0;
  // Include the bilateral (finer) edges of eq. 5.
  bool fine_edges = true;
};

// The cols x rows grid of pitch_px squares from (0, 0), morphed to the edges of `target` (the
// part of the grid outside the target sees no edges). Vertices (cols + 1) x (rows + 1) joined
// to their 8 neighbours by springs, pulled by -w grad P, damped, integrated to equilibrium.
// Corners stay fixed; the other border vertices slide along their border.
//
// Fabricability holds after every step (a move that would break it is shortened, down to no
// move, and that vertex's velocity is zeroed): every cell (vertices (c,r), (c+1,r),
// (c+1,r+1), (c,r+1)) is a convex quad, clockwise on screen, whose interior angles lie within
// [min_angle_deg, 180 - min_angle_deg], whose four edges are >= min_edge_px and whose
// "heights" (distance of each vertex to the line of each edge it is not on) are >=
// min_edge_px. Since all cells stay positively oriented and the border stays the rectangle,
// no two grid edges cross.
//
// Returns vertical[i] = vertices (i, 0..rows) top to bottom, horizontal[j] = vertices
// (0..cols, j) left to right, in px. Throws std::invalid_argument when cols or rows < 1,
// pitch_px <= 0, or the regular grid itself breaks the constraints (pitch_px < min_edge_px).
GridLines morph_grid(const cv::Mat& target, int cols, int rows, double pitch_px,
                     double min_edge_px, const MorphSettings& settings = {});

}  // namespace atelier::parquetry
