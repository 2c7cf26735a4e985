#include "algorithms/laser/kerf.h"

#include <polyclipping/clipper.hpp>

#include <algorithm>
#include <cmath>

#include "algorithms/laser/nesting.h"

namespace atelier::laser {
namespace {

constexpr double kScale = 1000.0;  // Clipper works on integers: 1 unit = 1 µm

ClipperLib::Path to_clipper(const Path& path) {
  ClipperLib::Path out;
  out.reserve(path.points.size());
  for (Point p : path.points) {
    out.emplace_back(static_cast<ClipperLib::cInt>(std::llround(p.x * kScale)),
                     static_cast<ClipperLib::cInt>(std::llround(p.y * kScale)));
  }
  return out;
}

Path from_clipper(const ClipperLib::Path& path) {
  Path out;
  out.closed = true;
  out.points.reserve(path.size());
  for (const auto& p : path) {
    out.points.push_back(
        Point{static_cast<double>(p.X) / kScale, static_cast<double>(p.Y) / kScale});
  }
  return out;
}

}  // namespace

std::vector<size_t> nesting_depths(const std::vector<Path>& paths) {
  const auto containers = containing_paths(paths);
  std::vector<size_t> depths(paths.size(), 0);
  for (size_t i = 0; i < paths.size(); ++i)
    for (size_t c : containers[i])
      if (paths[c].closed) ++depths[i];
  return depths;
}

KerfResult apply_kerf(const std::vector<Path>& paths, double kerf_mm, double arc_tolerance_mm) {
  if (kerf_mm <= 0) return KerfResult{paths, 0};
  return apply_kerf(paths, kerf_mm, nesting_depths(paths), arc_tolerance_mm);
}

KerfResult apply_kerf(const std::vector<Path>& paths, double kerf_mm, const std::vector<size_t>& depths,
                      double arc_tolerance_mm) {
  KerfResult result;
  if (kerf_mm <= 0) {
    result.paths = paths;
    return result;
  }
  for (size_t i = 0; i < paths.size(); ++i) {
    const Path& p = paths[i];
    // Lines and zero-area "closed" paths have no inside to keep; burn them as drawn.
    if (!p.closed || p.points.size() < 3 || std::fabs(signed_area(p.points)) < 1e-9) {
      result.paths.push_back(p);
      continue;
    }
    const bool hole = depths.at(i) % 2 == 1;
    ClipperLib::ClipperOffset offset(2.0, std::max(arc_tolerance_mm, 0.001) * kScale);
    offset.AddPath(to_clipper(p), ClipperLib::jtRound, ClipperLib::etClosedPolygon);
    ClipperLib::Paths out;
    offset.Execute(out, (hole ? -kerf_mm : kerf_mm) / 2 * kScale);
    if (out.empty()) {
      ++result.vanished_holes;
      continue;
    }
    for (const auto& o : out) result.paths.push_back(from_clipper(o));
  }
  return result;
}

}  // namespace atelier::laser
