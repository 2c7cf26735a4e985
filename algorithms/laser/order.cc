#include "algorithms/laser/order.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <utility>

#include "algorithms/laser/nesting.h"
#include "algorithms/laser/spatial_index.h"

namespace atelier::laser {
namespace {

// Where the head would enter `path`: the vertex index and whether to run it backwards.
struct Entry {
  double dist = std::numeric_limits<double>::infinity();
  size_t vertex = 0;
  bool reversed = false;
};

// One entry point in the index: path and vertex.
struct Candidate {
  size_t path = 0, vertex = 0;
  bool operator==(const Candidate& o) const { return path == o.path && vertex == o.vertex; }
};

struct ValueIndexable {
  using result_type = index::BPoint;
  const index::BPoint& operator()(const std::pair<index::BPoint, Candidate>& v) const { return v.first; }
};

// Values are told apart by their path and vertex alone (two paths may share a point).
struct ValueEqual {
  bool operator()(const std::pair<index::BPoint, Candidate>& a,
                  const std::pair<index::BPoint, Candidate>& b) const {
    return a.second == b.second;
  }
};

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

  // The entry points of the paths allowed next (every vertex of a closed path, both ends of
  // an open one), in an R-tree: a path's points go in when its last blocker is burned and
  // come out when it is burned itself.
  using Value = std::pair<index::BPoint, Candidate>;
  auto entries_of = [&](size_t i, std::vector<Value>& out) {
    const auto& pts = paths[i].points;
    if (paths[i].closed) {
      for (size_t v = 0; v < pts.size(); ++v) out.push_back({index::to_bpoint(pts[v]), Candidate{i, v}});
    } else {
      out.push_back({index::to_bpoint(pts.front()), Candidate{i, 0}});
      if (pts.size() > 1) out.push_back({index::to_bpoint(pts.back()), Candidate{i, pts.size() - 1}});
    }
  };
  std::vector<Value> initial;
  for (size_t i = 0; i < n; ++i)
    if (blockers[i] == 0) entries_of(i, initial);
  index::bgi::rtree<Value, index::Params, ValueIndexable, ValueEqual> tree(initial.begin(), initial.end());

  std::vector<Path> out;
  out.reserve(n);
  std::vector<Value> near, batch;
  for (size_t step = 0; step < n; ++step) {
    // Containment is acyclic (strictly growing area), so some path is always allowed.
    near.clear();
    tree.query(index::bgi::nearest(index::to_bpoint(head), 1), std::back_inserter(near));
    // Exactly as a scan of every allowed path would choose: the smallest distance, then the
    // lowest path index, then the lowest vertex (an open path's front before its back). Ties
    // are gathered from a box just larger than the nearest distance.
    const double d0 = distance(head, Point{near[0].first.get<0>(), near[0].first.get<1>()});
    const double r = d0 * (1 + 1e-9) + 1e-12;
    near.clear();
    tree.query(index::bgi::intersects(index::BBox(index::BPoint(head.x - r, head.y - r),
                                                  index::BPoint(head.x + r, head.y + r))),
               std::back_inserter(near));
    Entry best_e;
    Candidate best{n, 0};
    for (const auto& [pt, c] : near) {
      const double d = distance(head, Point{pt.get<0>(), pt.get<1>()});
      if (d < best_e.dist || (d == best_e.dist && (c.path < best.path ||
                                                   (c.path == best.path && c.vertex < best.vertex)))) {
        best_e = Entry{d, c.vertex, !paths[c.path].closed && c.vertex > 0};
        best = c;
      }
    }
    batch.clear();
    entries_of(best.path, batch);
    for (const auto& v : batch) tree.remove(v);
    for (size_t c : containers[best.path]) {
      if (--blockers[c] == 0) {
        batch.clear();
        entries_of(c, batch);
        tree.insert(batch.begin(), batch.end());
      }
    }
    out.push_back(entered(paths[best.path], best_e));
    const Path& p = out.back();
    head = p.closed ? p.points.front() : p.points.back();
  }
  return out;
}

}  // namespace atelier::laser
