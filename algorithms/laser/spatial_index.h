// Boost.Geometry R-tree types for the laser planner's spatial queries (which closed paths
// may contain a path; which path vertex is nearest to the head). Units: mm.
//
// Header-only types; an index is not thread-safe while it is modified.
#pragma once

#include <boost/geometry.hpp>
#include <boost/geometry/geometries/box.hpp>
#include <boost/geometry/geometries/point.hpp>
#include <boost/geometry/index/rtree.hpp>

#include <cstddef>
#include <utility>

#include "algorithms/laser/geometry.h"

namespace atelier::laser::index {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;

using BPoint = bg::model::point<double, 2, bg::cs::cartesian>;
using BBox = bg::model::box<BPoint>;

inline BPoint to_bpoint(Point p) { return BPoint(p.x, p.y); }
inline BBox to_bbox(const Bounds& b) { return BBox(BPoint(b.min_x, b.min_y), BPoint(b.max_x, b.max_y)); }

// R*-tree nodes of up to 16 values: good query speed for both bulk-loaded and updated trees.
using Params = bgi::rstar<16>;

}  // namespace atelier::laser::index
