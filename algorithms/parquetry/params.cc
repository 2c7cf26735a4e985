#include "algorithms/parquetry/params.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace atelier::parquetry {

const char* order_name(Order order) { return order == Order::center ? "center" : "saliency"; }

Order order_from_name(const std::string& name) {
  if (name == "saliency") return Order::saliency;
  if (name == "center") return Order::center;
  throw std::invalid_argument("parquetry: order must be 'saliency' or 'center', not '" + name +
                              "'");
}

const char* grid_name(Grid grid) { return grid == Grid::morphed ? "morphed" : "regular"; }

Grid grid_from_name(const std::string& name) {
  if (name == "regular") return Grid::regular;
  if (name == "morphed") return Grid::morphed;
  throw std::invalid_argument("parquetry: grid must be 'regular' or 'morphed', not '" + name + "'");
}

const char* refine_name(Refine refine) { return refine == Refine::dp ? "dp" : "none"; }

Refine refine_from_name(const std::string& name) {
  if (name == "none") return Refine::none;
  if (name == "dp") return Refine::dp;
  throw std::invalid_argument("parquetry: refine must be 'none' or 'dp', not '" + name + "'");
}

void validate(const Params& p) {
  auto fail = [](const std::string& what) {
    throw std::invalid_argument("parquetry: " + what);
  };
  auto weight = [&](const char* name, double w) {
    if (!(w >= 0 && w <= 1)) fail(std::string(name) + " must be in [0, 1]");
  };
  weight("w_intens", p.w_intens);
  weight("w_edge", p.w_edge);
  weight("w_hist", p.w_hist);
  if (p.w_intens == 0 && p.w_edge == 0) fail("w_intens and w_edge cannot both be 0");
  if (!(p.px_per_mm > 0 && p.px_per_mm <= 20)) fail("px_per_mm must be in (0, 20]");
  if (!(p.patch_mm >= kMinPatchMm)) fail("patch_mm must be at least 5 mm (smaller pieces get lost)");
  if (std::lround(p.patch_mm * p.px_per_mm) < 2) {
    fail("patch_mm * px_per_mm must be at least 2 pixels");
  }
  if (!(p.size_mm >= p.patch_mm)) fail("size_mm must be at least patch_mm");
  if (p.rotations < 1 || p.rotations > 360) fail("rotations must be in [1, 360]");
  if (p.adaptive_levels < 0 || p.adaptive_levels > 4) fail("adaptive_levels must be in [0, 4]");
  if (!(p.adaptive_factor >= 0)) fail("adaptive_factor must be >= 0");
  if (!(p.kerf_mm >= 0 && p.kerf_mm <= 2)) fail("kerf_mm must be in [0, 2]");
  if (!(p.min_feature_mm > 0 && p.min_feature_mm <= kMinPatchMm)) {
    fail("min_feature_mm must be in (0, 5]");
  }
  if (!(p.overlap > 0 && p.overlap <= 0.5)) fail("overlap must be in (0, 0.5]");
  if (p.grid == Grid::morphed && p.refine == Refine::dp) {
    fail("grid = morphed and refine = dp are alternatives (paper 3.4); choose one");
  }
  if (p.adaptive_levels > 0 && (p.grid != Grid::regular || p.refine != Refine::none)) {
    fail("adaptive_levels needs the regular grid without refinement");
  }
  if (p.refine == Refine::dp) {
    const int patch = patch_px(p);
    const int half = std::max(1, static_cast<int>(std::lround(p.overlap * patch / 2)));
    if ((patch - 2 * half) / working_px_per_mm(p) < kMinPatchMm - 1e-9) {
      fail("refine = dp needs patch_mm large enough that the part of a patch outside the "
           "overlaps stays at least 5 mm (raise patch_mm or px_per_mm, or lower overlap)");
    }
  }
}

int patch_px(const Params& p) {
  const int unit = 1 << std::clamp(p.adaptive_levels, 0, 4);
  const long whole = std::lround(p.patch_mm * p.px_per_mm / unit) * unit;
  return static_cast<int>(std::max<long>({2, unit, whole}));
}

double working_px_per_mm(const Params& p) { return patch_px(p) / p.patch_mm; }

}  // namespace atelier::parquetry
