// Helpers shared by the Hershey text and font tests: a font by name, and whether two texts
// have the same strokes.
#pragma once

#include <string>
#include <vector>

#include "algorithms/laser/geometry.h"
#include "algorithms/laser/hershey_text.h"
#include "convert/common/hershey_fonts.h"

namespace atelier::laser::testing {

inline const HersheyFont& font_named(const std::string& name) { return atelier::hershey_font(name); }

inline bool same_strokes(const std::vector<Path>& a, const std::vector<Path>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].points.size() != b[i].points.size()) return false;
    for (size_t j = 0; j < a[i].points.size(); ++j)
      if (distance(a[i].points[j], b[i].points[j]) > 1e-9) return false;
  }
  return true;
}

}  // namespace atelier::laser::testing
