#include "algorithms/laser/nesting.h"

#include <algorithm>
#include <cmath>

namespace atelier::laser {
namespace {

// Up to this many vertices of the inner path are tested: enough for a majority vote that
// tolerates vertices lying on the outer path's boundary, cheap for long paths.
constexpr size_t kSamples = 9;

bool encloses_majority(const Path& outer, const Path& inner) {
  const auto& pts = inner.points;
  size_t step = std::max<size_t>(1, pts.size() / kSamples);
  size_t tested = 0, inside = 0;
  for (size_t i = 0; i < pts.size(); i += step) {
    ++tested;
    if (point_in_polygon(pts[i], outer.points)) ++inside;
  }
  return tested > 0 && 2 * inside > tested;
}

}  // namespace

std::vector<std::vector<size_t>> containing_paths(const std::vector<Path>& paths) {
  const size_t n = paths.size();
  std::vector<Bounds> box(n);
  std::vector<double> area(n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    box[i] = bounds_of(paths[i]);
    if (paths[i].closed) area[i] = std::fabs(signed_area(paths[i].points));
  }
  std::vector<std::vector<size_t>> result(n);
  for (size_t b = 0; b < n; ++b) {
    if (!paths[b].closed || paths[b].points.size() < 3 || area[b] <= 0) continue;
    for (size_t a = 0; a < n; ++a) {
      if (a == b || paths[a].points.empty() || !box[b].contains(box[a])) continue;
      if (paths[a].closed && area[a] >= area[b]) continue;
      if (encloses_majority(paths[b], paths[a])) result[a].push_back(b);
    }
  }
  return result;
}

}  // namespace atelier::laser
