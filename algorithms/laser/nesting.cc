#include "algorithms/laser/nesting.h"

#include <algorithm>
#include <cmath>

#include "algorithms/laser/spatial_index.h"

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
  // Only closed paths with an area can contain anything: those go in an R-tree of their
  // bounding boxes, so each path tests just the candidates whose box covers its own.
  using Entry = std::pair<index::BBox, size_t>;
  std::vector<Entry> containers;
  for (size_t i = 0; i < n; ++i) {
    box[i] = bounds_of(paths[i]);
    if (paths[i].closed) area[i] = std::fabs(signed_area(paths[i].points));
    if (paths[i].closed && paths[i].points.size() >= 3 && area[i] > 0)
      containers.emplace_back(index::to_bbox(box[i]), i);
  }
  const index::bgi::rtree<Entry, index::Params> tree(containers.begin(), containers.end());
  std::vector<std::vector<size_t>> result(n);
  std::vector<Entry> found;
  for (size_t a = 0; a < n; ++a) {
    if (paths[a].points.empty()) continue;
    found.clear();
    tree.query(index::bgi::covers(index::to_bbox(box[a])), std::back_inserter(found));
    for (const auto& [ignored, b] : found) {
      if (a == b) continue;
      if (paths[a].closed && area[a] >= area[b]) continue;
      if (encloses_majority(paths[b], paths[a])) result[a].push_back(b);
    }
    std::sort(result[a].begin(), result[a].end());
  }
  return result;
}

}  // namespace atelier::laser
