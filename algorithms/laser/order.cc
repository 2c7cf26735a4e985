#include "algorithms/laser/order.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "algorithms/laser/nesting.h"

namespace atelier::laser {
namespace {

double distance_to_box(Point p, const Bounds& b) {
  double dx = std::max({b.min_x - p.x, 0.0, p.x - b.max_x});
  double dy = std::max({b.min_y - p.y, 0.0, p.y - b.max_y});
  return std::hypot(dx, dy);
}

// Where the head would enter `path`: the vertex index and whether to run it backwards.
struct Entry {
  double dist = std::numeric_limits<double>::infinity();
  size_t vertex = 0;
  bool reversed = false;
};

Entry best_entry(const Path& path, Point head) {
  Entry e;
  const auto& pts = path.points;
  if (path.closed) {
    for (size_t i = 0; i < pts.size(); ++i) {
      double d = distance(head, pts[i]);
      if (d < e.dist) e = Entry{d, i, false};
    }
  } else {
    e = Entry{distance(head, pts.front()), 0, false};
    double back = distance(head, pts.back());
    if (back < e.dist) e = Entry{back, pts.size() - 1, true};
  }
  return e;
}

Path entered(const Path& path, const Entry& e) {
  Path out;
  out.closed = path.closed;
  if (path.closed) {
    out.points.assign(path.points.begin() + static_cast<long>(e.vertex), path.points.end());
    out.points.insert(out.points.end(), path.points.begin(),
                      path.points.begin() + static_cast<long>(e.vertex));
  } else {
    out.points = path.points;
    if (e.reversed) std::reverse(out.points.begin(), out.points.end());
  }
  return out;
}

}  // namespace

std::vector<Path> order_paths(const std::vector<Path>& input, Point& head) {
  std::vector<Path> paths;
  for (const auto& p : input)
    if (!p.points.empty()) paths.push_back(p);
  const size_t n = paths.size();
  const auto containers = containing_paths(paths);
  // blockers[c]: paths inside closed path c that are not burned yet.
  std::vector<size_t> blockers(n, 0);
  for (const auto& list : containers)
    for (size_t c : list) ++blockers[c];
  std::vector<Bounds> box(n);
  for (size_t i = 0; i < n; ++i) box[i] = bounds_of(paths[i]);

  std::vector<bool> done(n, false);
  std::vector<Path> out;
  out.reserve(n);
  for (size_t step = 0; step < n; ++step) {
    size_t best = n;
    Entry best_e;
    for (size_t i = 0; i < n; ++i) {
      if (done[i] || blockers[i] > 0) continue;
      if (distance_to_box(head, box[i]) >= best_e.dist) continue;  // cannot beat the best
      Entry e = best_entry(paths[i], head);
      if (e.dist < best_e.dist || best == n) {
        best = i;
        best_e = e;
      }
    }
    // Containment is acyclic (strictly growing area), so some path is always allowed.
    done[best] = true;
    for (size_t c : containers[best]) --blockers[c];
    out.push_back(entered(paths[best], best_e));
    const Path& p = out.back();
    head = p.closed ? p.points.front() : p.points.back();
  }
  return out;
}

}  // namespace atelier::laser
