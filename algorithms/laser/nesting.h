// Which closed paths contain which paths (for cut order and kerf direction).
//
// Candidates come from an R-tree of the closed paths' bounding boxes: O(n log n) for n
// paths plus the tests of boxes that do cover each other.
//
// Pure; thread-safe. Units: mm.
#pragma once

#include <cstddef>
#include <vector>

#include "algorithms/laser/geometry.h"

namespace atelier::laser {

// For each path, the indices of the closed paths that contain it. A closed path B contains
// path A when B's bounding box holds A's, B encloses more than half of A's vertices
// (even-odd rule) and, when A is closed too, B's area is strictly larger (so duplicates
// never contain each other and the relation has no cycles). Open paths contain nothing.
std::vector<std::vector<size_t>> containing_paths(const std::vector<Path>& paths);

}  // namespace atelier::laser
