// Parameters of a parquetry plan (paper table 1), named as the keys of `[parquetry]`.
//
// Units: mm for geometry; `px_per_mm` is the working resolution at which target and wood are
// compared (features, matching, masks, reconstruction). Pure data; validate() throws
// std::invalid_argument naming the parameter.
#pragma once

#include <cstdint>
#include <string>

namespace atelier::parquetry {

// Order of the priority queue of target patches (paper 3.3, figure 6).
enum class Order { saliency, center };
const char* order_name(Order order);                 // "saliency", "center"
Order order_from_name(const std::string& name);      // throws std::invalid_argument

// Patch shapes (paper 3.4): a regular grid of squares, or the grid morphed a priori to the
// target's edges (eq. 5-7). The two refinements are alternatives, as in the paper.
enum class Grid { regular, morphed };
const char* grid_name(Grid grid);                    // "regular", "morphed"
Grid grid_from_name(const std::string& name);

// A-posteriori cut refinement (paper 3.4, eq. 8-9): none, or dynamic-programming cuts in
// the overlaps of enlarged patches (regular grid only).
enum class Refine { none, dp };
const char* refine_name(Refine refine);              // "none", "dp"
Refine refine_from_name(const std::string& name);

struct Params {
  double size_mm = 360;      // shorter side of the result (trimmed down to whole patches)
  double patch_mm = 14;      // edge of a square patch before adaptive splitting
  int rotations = 15;        // rotated copies of every sheet, at k * 360 / rotations degrees
  double w_intens = 0.5;     // weight of the intensity feature (eq. 1)
  double w_edge = 0.5;       // weight of the Sobel edge feature (eq. 1)
  double w_hist = 0.5;       // interpolation towards the histogram-matched target (eq. 2)
  int adaptive_levels = 0;   // how many times a patch may be split in four (paper 3.3)
  double adaptive_factor = 1.2;  // split when the four children cost < factor * the whole
  Order order = Order::saliency;
  std::uint64_t seed = 0;    // breaks ties in the patch order
  Grid grid = Grid::regular;
  Refine refine = Refine::none;
  // Width of the overlap band of refine = dp, as a fraction of patch_mm (Efros & Freeman use
  // 1/6; wider bands give the cuts more room and use more wood).
  double overlap = 0.3;
  // Laser kerf: pieces on a sheet keep at least this much wood between them, so cutting one
  // never burns into another (the cut layer compensates by kerf_mm / 2 outwards).
  double kerf_mm = 0.2;
  // Thinnest part a piece may have anywhere (slivers break or burn away).
  double min_feature_mm = 2.0;
  // Working resolution. 0.5 px/mm (2 mm pixels, a 14 mm patch is 7x7 px) keeps the paper's
  // eye (28x17 patches, 15 rotations, 12 sheets) under 10 s on 2 cores; matching cost grows
  // with the square of this. The plan works at working_px_per_mm(), this nudged so that a
  // patch is a whole number of pixels: the pieces are always patch_mm, whatever the
  // resolution.
  double px_per_mm = 0.5;
};

// Smallest patch edge the workshop can cut and assemble (paper 4.1).
inline constexpr double kMinPatchMm = 5.0;

void validate(const Params& params);

// The resolution a plan works at (px per mm): px_per_mm moved to the nearest value at which
// patch_mm is a whole number of pixels, a multiple of 2^adaptive_levels (so quarters split
// exactly) and at least 2. A 9.144 mm patch at 0.5 px/mm is 5 px at 0.547 px/mm, not 10 mm
// of 5 px at 0.5. Needs a valid patch_mm and adaptive_levels.
double working_px_per_mm(const Params& params);

// Edge of a patch in working pixels: patch_mm * working_px_per_mm(), exact.
int patch_px(const Params& params);

}  // namespace atelier::parquetry
