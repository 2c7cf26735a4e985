#include "algorithms/parquetry/params.h"

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
}

}  // namespace atelier::parquetry
