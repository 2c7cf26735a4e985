// Cut order within one layer: inner paths before the closed paths that contain them, and
// short travel by nearest neighbour among the paths allowed next.
//
// The next path comes from an R-tree of the allowed paths' entry points: O(v log v) for v
// entry points (vertices of closed paths, ends of open ones), choosing exactly what a scan of
// every allowed path would (ties: the lower path index, then the lower vertex).
//
// Pure; thread-safe. Units: mm.
#pragma once

#include <vector>

#include "algorithms/laser/geometry.h"

namespace atelier::laser {

// Returns `paths` in burn order. Closed paths are rotated to start at the vertex nearest to
// the head; open paths may be reversed. `head` is where the head is before the first path
// and is updated to where the last path ends. Empty paths are dropped.
std::vector<Path> order_paths(const std::vector<Path>& paths, Point& head);

}  // namespace atelier::laser
