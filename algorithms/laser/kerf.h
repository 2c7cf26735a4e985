// Kerf compensation with Clipper (ClipperLib::ClipperOffset, round joins).
//
// The beam removes a strip kerf_mm wide centred on its path, so closed paths are offset by
// kerf_mm / 2: outer boundaries (even nesting depth among the closed paths) grow, holes
// (odd depth) shrink, and the cut pieces keep their drawn size. Open paths are unchanged.
// Pure; thread-safe. Units: mm.
#pragma once

#include <cstddef>
#include <vector>

#include "algorithms/laser/geometry.h"

namespace atelier::laser {

struct KerfResult {
  std::vector<Path> paths;   // in input order; a split hole gives several
  size_t vanished_holes = 0; // holes smaller than the kerf: nothing is left to cut
};

// `kerf_mm` <= 0 returns the input unchanged. Coordinates are scaled to integers at
// 1000 per mm (1 µm resolution); round joins are approximated within `arc_tolerance_mm`.
KerfResult apply_kerf(const std::vector<Path>& paths, double kerf_mm,
                      double arc_tolerance_mm = 0.01);
// The same with the nesting depth of each path given (how many closed paths contain it),
// counted over every cut layer: a hole drawn in another colour than its outline still
// shrinks.
KerfResult apply_kerf(const std::vector<Path>& paths, double kerf_mm, const std::vector<size_t>& depths,
                      double arc_tolerance_mm = 0.01);

// For each path, how many closed paths of `paths` contain it.
std::vector<size_t> nesting_depths(const std::vector<Path>& paths);

}  // namespace atelier::laser
