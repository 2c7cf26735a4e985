// Shapes and G-code helpers shared by the laser unit tests.
#pragma once

#include <sstream>
#include <string>
#include <vector>

#include "algorithms/laser/geometry.h"
#include "algorithms/laser/plan.h"

namespace atelier::laser::testing {

// Axis-aligned closed square in design coordinates, corner (x, y), side `size` mm.
inline Path square(double x, double y, double size) {
  return Path{{{x, y}, {x + size, y}, {x + size, y + size}, {x, y + size}}, true};
}

inline Layer layer(const std::string& name, Mode mode, std::vector<Path> paths) {
  Layer l;
  l.settings.name = name;
  l.settings.mode = mode;
  l.settings.color = "#000000";
  l.paths = std::move(paths);
  return l;
}

inline std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

inline double width_of(const Path& p) { return bounds_of(p).max_x - bounds_of(p).min_x; }

}  // namespace atelier::laser::testing
