// Skeleton branches (paper 5.2, Fig. 6) and the B-spline through a branch.
#include "algorithms/embroidery/skeleton.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc.hpp>

namespace atelier::embroidery {
namespace {

// Neighbour offsets, orthogonal first: the trace prefers them so a staircase corner pixel is
// never skipped by a diagonal step.
constexpr std::array<int, 8> kDx = {1, 0, -1, 0, 1, -1, -1, 1};
constexpr std::array<int, 8> kDy = {0, 1, 0, -1, 1, 1, -1, -1};
// The 8 neighbours in circular order (for the crossing number).
constexpr std::array<int, 8> kCx = {0, 1, 1, 1, 0, -1, -1, -1};
constexpr std::array<int, 8> kCy = {-1, -1, 0, 1, 1, 1, 0, -1};

bool adjacent(cv::Point a, cv::Point b) {
  return std::abs(a.x - b.x) <= 1 && std::abs(a.y - b.y) <= 1;
}

// The 8-connected groups among a pixel's set neighbours. A 4-neighbour touches the ring
// positions one and two away (N and E are diagonal neighbours), a corner only its two sides.
int neighbour_groups(const cv::Mat1b& skel, int x, int y, int* count = nullptr) {
  std::array<bool, 8> on;
  std::array<int, 8> parent;
  int n = 0;
  for (int k = 0; k < 8; ++k) {
    on[k] = skel(y + kCy[k], x + kCx[k]) != 0;
    parent[k] = k;
    n += on[k];
  }
  if (count) *count = n;
  auto root = [&](int a) {
    while (parent[a] != a) a = parent[a];
    return a;
  };
  for (int k = 0; k < 8; ++k) {
    if (!on[k]) continue;
    const int reach = (k % 2 == 0) ? 2 : 1;  // even ring positions are N, E, S, W
    for (int r = 1; r <= reach; ++r) {
      const int j = (k + r) % 8;
      if (on[j]) parent[root(j)] = root(k);
    }
  }
  int groups = 0;
  for (int k = 0; k < 8; ++k) groups += on[k] && root(k) == k;
  return groups;
}

// Zhang-Suen leaves 4-connected staircases ("##" steps); a step corner with two perpendicular
// 4-neighbours that stay connected without it would look like a junction. Remove those.
void remove_staircase_corners(cv::Mat1b& skel) {
  for (int y = 1; y < skel.rows - 1; ++y)
    for (int x = 1; x < skel.cols - 1; ++x) {
      if (!skel(y, x)) continue;
      const bool n = skel(y - 1, x), e = skel(y, x + 1), s = skel(y + 1, x), w = skel(y, x - 1);
      if (!((n && e) || (e && s) || (s && w) || (w && n))) continue;
      int count = 0;
      if (neighbour_groups(skel, x, y, &count) == 1 && count >= 2 && count <= 3) skel(y, x) = 0;
    }
}

// A pixel joins three or more arms when its set neighbours form three or more groups, or
// when it sits in a clump (three or more neighbours in two groups): thinning turns a crossing
// of thick strokes into a small blob in which no single pixel separates three arms.
bool is_junction(const cv::Mat1b& skel, int x, int y) {
  int count = 0;
  const int groups = neighbour_groups(skel, x, y, &count);
  return groups >= 3 || (groups == 2 && count >= 3);
}

// Greedy walk from `start` through unvisited pixels of label `id`.
std::vector<cv::Point> walk(const cv::Mat1i& labels, cv::Mat1b& visited, cv::Point start, int id) {
  std::vector<cv::Point> path;
  cv::Point p = start;
  for (;;) {
    bool moved = false;
    for (int k = 0; k < 8 && !moved; ++k) {
      const cv::Point q(p.x + kDx[k], p.y + kDy[k]);
      if (labels(q) == id && !visited(q)) {
        visited(q) = 1;
        path.push_back(q);
        p = q;
        moved = true;
      }
    }
    if (!moved) return path;
  }
}

struct Segment {
  std::vector<cv::Point> px;  // padded frame
  std::array<int, 2> area{{0, 0}};  // area label touching each end (0 = free end)
  bool closed = false;
  bool dropped = false;
};

struct End {
  int seg, which;
  cv::Point2f dir;  // pointing out of the segment, into the area
};

int find_root(std::vector<int>& parent, int a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

cv::Point2f end_direction(const Segment& s, int which, cv::Point2f area_centre) {
  const int n = static_cast<int>(s.px.size());
  const int k = std::min(n - 1, 8);
  const cv::Point e = which == 0 ? s.px[0] : s.px[n - 1];
  cv::Point2f d;
  if (k >= 2) {
    const cv::Point b = which == 0 ? s.px[k] : s.px[n - 1 - k];
    d = cv::Point2f(e - b);
  } else {
    d = area_centre - cv::Point2f(e);
  }
  const float len = std::hypot(d.x, d.y);
  return len > 0 ? d * (1.0f / len) : cv::Point2f(0, 0);
}

// Best pairing of the arms at one area: maximal total continuity (-dot of the two outward
// directions), pairs with continuity <= 0 (a turn of 90 degrees or more) not allowed.
std::vector<std::pair<int, int>> pair_ends(const std::vector<End>& ends) {
  const int n = static_cast<int>(ends.size());
  auto sim = [&](int a, int b) { return -(ends[a].dir.dot(ends[b].dir)); };
  std::vector<std::pair<int, int>> best, cur;
  if (n > 10) {  // rare; greedy keeps it cheap
    std::vector<std::tuple<float, int, int>> c;
    for (int a = 0; a < n; ++a)
      for (int b = a + 1; b < n; ++b)
        if (sim(a, b) > 0) c.emplace_back(-sim(a, b), a, b);
    std::sort(c.begin(), c.end());
    std::vector<bool> used(n, false);
    for (auto& [s, a, b] : c)
      if (!used[a] && !used[b]) {
        used[a] = used[b] = true;
        best.emplace_back(a, b);
      }
    return best;
  }
  float best_score = -1;
  std::vector<bool> used(n, false);
  std::function<void(float)> rec = [&](float score) {
    int i = 0;
    while (i < n && used[i]) ++i;
    if (i == n) {
      if (score > best_score) {
        best_score = score;
        best = cur;
      }
      return;
    }
    used[i] = true;
    rec(score);  // leave i alone
    for (int j = i + 1; j < n; ++j) {
      if (used[j] || sim(i, j) <= 0) continue;
      used[j] = true;
      cur.emplace_back(i, j);
      rec(score + sim(i, j));
      cur.pop_back();
      used[j] = false;
    }
    used[i] = false;
  };
  rec(0);
  return best;
}

}  // namespace

bool is_closed(const SkeletonBranch& b) {
  return b.pixels.size() >= 3 && std::abs(b.pixels.front().x - b.pixels.back().x) <= 1.5f &&
         std::abs(b.pixels.front().y - b.pixels.back().y) <= 1.5f;
}

namespace {

// OpenCV's thinning costs every pixel of the image on every pass, stroke or not. Thinning is
// local (a pass looks at 3x3 neighbours; a stroke of half width r is thinned in about r + 1
// iterations, two passes each), so a sparse image is thinned tile by tile with a margin the
// passes cannot see across, and only tiles holding stroke pixels are thinned at all.
cv::Mat1b thin(const cv::Mat1b& mask, double max_half_width) {
  cv::Mat1b skel;
  const int tile = 48, margin = 2 * static_cast<int>(std::ceil(max_half_width)) + 6;
  std::vector<std::pair<cv::Rect, cv::Rect>> tiles;  // interior, interior + margin
  if (mask.total() > 4 * (tile + 2 * margin) * (tile + 2 * margin)) {
    cv::Mat1i sum;
    cv::integral(mask, sum, CV_32S);
    const cv::Rect all(0, 0, mask.cols, mask.rows);
    size_t area = 0;
    for (int y = 0; y < mask.rows; y += tile)
      for (int x = 0; x < mask.cols; x += tile) {
        const cv::Rect in = cv::Rect(x, y, tile, tile) & all;
        if (sum(in.br()) - sum(in.y, in.br().x) - sum(in.br().y, in.x) + sum(in.tl()) == 0) continue;
        tiles.emplace_back(in, cv::Rect(x - margin, y - margin, tile + 2 * margin, tile + 2 * margin) & all);
        area += tiles.back().second.area();
      }
    if (2 * area > mask.total()) tiles.clear();  // dense: one pass over the image is cheaper
  }
  if (tiles.empty()) {
    cv::ximgproc::thinning(mask, skel, cv::ximgproc::THINNING_ZHANGSUEN);
    return skel;
  }
  skel = cv::Mat1b(mask.size(), uchar(0));
  cv::Mat1b part;
  for (const auto& [in, out] : tiles) {
    cv::ximgproc::thinning(mask(out), part, cv::ximgproc::THINNING_ZHANGSUEN);
    part(in - out.tl()).copyTo(skel(in));
  }
  return skel;
}

// padded1 / dist1, when given: mask_in > 0 with a 1-pixel zero border, and its distance
// transform (DIST_L2, 3x3), which the caller already has. Every interior path to the outer of
// two zero rings crosses the inner one, so the 2-pixel-border transform is dist1 with a zero
// ring around it, exactly; it need not be computed again.
std::vector<SkeletonBranch> branches_of(const cv::Mat1b& mask_in, double min_branch_px, double max_half_width,
                                        const cv::Mat1b* padded1 = nullptr, const cv::Mat1f* dist1 = nullptr) {
  std::vector<SkeletonBranch> out;
  // A 2-pixel zero border: neighbour lookups never leave the image.
  cv::Mat1b mask;
  if (padded1)
    cv::copyMakeBorder(*padded1, mask, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
  else
    cv::copyMakeBorder(mask_in > 0, mask, 2, 2, 2, 2, cv::BORDER_CONSTANT, 0);
  // Thinning never touches an image's outermost ring, so one zero ring is enough for it: thin
  // the inner view (for a small region the second ring is a good part of the work).
  cv::Mat1b skel(mask.size(), uchar(0));
  const cv::Rect inner(1, 1, mask.cols - 2, mask.rows - 2);
  thin(mask(inner), max_half_width).copyTo(skel(inner));
  remove_staircase_corners(skel);
  cv::Mat1f dist;
  if (dist1)
    cv::copyMakeBorder(*dist1, dist, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
  else
    cv::distanceTransform(mask, dist, cv::DIST_L2, 3);

  // Intersection areas: skeleton pixels within the local stroke radius (geodesically, along
  // the skeleton) of a junction pixel; near a crossing the thinned arms are bent.
  cv::Mat1b removed(skel.size(), uchar(0));
  std::vector<cv::Point> queue;
  cv::Mat1i steps(skel.size(), -1);
  for (int y = 1; y < skel.rows - 1; ++y)
    for (int x = 1; x < skel.cols - 1; ++x) {
      if (!skel(y, x) || !is_junction(skel, x, y)) continue;
      const int radius = static_cast<int>(std::ceil(std::max(1.5f, dist(y, x)))) + 1;
      queue.assign(1, cv::Point(x, y));
      std::vector<cv::Point> touched = queue;
      steps(y, x) = 0;
      for (size_t q = 0; q < queue.size(); ++q) {
        const cv::Point p = queue[q];
        removed(p) = 255;
        if (steps(p) >= radius) continue;
        for (int k = 0; k < 8; ++k) {
          const cv::Point n(p.x + kDx[k], p.y + kDy[k]);
          if (!skel(n) || steps(n) >= 0) continue;
          steps(n) = steps(p) + 1;
          queue.push_back(n);
          touched.push_back(n);
        }
      }
      for (const cv::Point& p : touched) steps(p) = -1;
    }
  cv::Mat1i area_label;
  const int n_areas = cv::connectedComponents(removed, area_label, 8, CV_32S);
  std::vector<cv::Point2f> area_centre(n_areas, cv::Point2f(0, 0));
  std::vector<int> area_count(n_areas, 0);
  for (int y = 0; y < removed.rows; ++y)
    for (int x = 0; x < removed.cols; ++x)
      if (const int a = area_label(y, x); a > 0) {
        area_centre[a] += cv::Point2f(x, y);
        ++area_count[a];
      }
  for (int a = 1; a < n_areas; ++a) area_centre[a] *= 1.0f / area_count[a];

  // The arms: what is left, traced pixel by pixel.
  cv::Mat1b rest = skel & ~removed;
  cv::Mat1i seg_label;
  const int n_segs = cv::connectedComponents(rest, seg_label, 8, CV_32S);
  std::vector<Segment> segs(n_segs);
  cv::Mat1b visited(skel.size(), uchar(0));
  for (int y = 0; y < rest.rows; ++y)
    for (int x = 0; x < rest.cols; ++x) {
      const int id = seg_label(y, x);
      if (id == 0 || visited(y, x)) continue;
      const cv::Point p0(x, y);
      visited(p0) = 1;
      std::vector<cv::Point> a = walk(seg_label, visited, p0, id);
      std::vector<cv::Point> b = walk(seg_label, visited, p0, id);
      Segment& s = segs[id];
      s.px.assign(b.rbegin(), b.rend());
      s.px.push_back(p0);
      s.px.insert(s.px.end(), a.begin(), a.end());
    }
  auto area_near = [&](cv::Point p) {
    for (int k = 0; k < 8; ++k)
      if (const int a = area_label(p.y + kDy[k], p.x + kDx[k]); a > 0) return a;
    return 0;
  };
  std::vector<int> parent(n_areas);
  std::iota(parent.begin(), parent.end(), 0);
  for (int i = 1; i < n_segs; ++i) {
    Segment& s = segs[i];
    if (s.px.empty()) {
      s.dropped = true;
      continue;
    }
    s.area = {area_near(s.px.front()), area_near(s.px.back())};
    const double len = static_cast<double>(s.px.size());
    s.closed = s.area[0] == 0 && s.area[1] == 0 && s.px.size() >= 3 &&
               adjacent(s.px.front(), s.px.back());
    const int at_areas = (s.area[0] > 0) + (s.area[1] > 0);
    if (len >= min_branch_px) continue;
    s.dropped = true;  // a spur, a short isolated piece, or a bridge between two areas
    if (at_areas == 2) parent[find_root(parent, s.area[0])] = find_root(parent, s.area[1]);
  }

  // Reconnect the arms at each (merged) area in pairs.
  std::vector<std::vector<End>> ends_at(n_areas);
  for (int i = 1; i < n_segs; ++i) {
    Segment& s = segs[i];
    if (s.dropped) continue;
    for (int w = 0; w < 2; ++w) {
      if (s.area[w] == 0) continue;
      s.area[w] = find_root(parent, s.area[w]);
      ends_at[s.area[w]].push_back({i, w, end_direction(s, w, area_centre[s.area[w]])});
    }
  }
  // link[seg*2+which] = partner seg*2+which, or -1.
  std::vector<int> link(2 * n_segs, -1);
  for (int a = 1; a < n_areas; ++a) {
    const std::vector<End>& ends = ends_at[a];
    if (ends.size() < 2) continue;
    for (auto [i, j] : pair_ends(ends)) {
      link[2 * ends[i].seg + ends[i].which] = 2 * ends[j].seg + ends[j].which;
      link[2 * ends[j].seg + ends[j].which] = 2 * ends[i].seg + ends[i].which;
    }
  }

  // Traverse again: chains of arms joined by straight pixel lines through the areas.
  std::vector<bool> used(n_segs, false);
  auto end_px = [&](int e) { return e % 2 == 0 ? segs[e / 2].px.front() : segs[e / 2].px.back(); };
  auto emit = [&](int first_seg, int first_which) {
    std::vector<cv::Point> px;
    int seg = first_seg, entry = first_which;  // the end we enter the segment by
    for (;;) {
      used[seg] = true;
      const auto& p = segs[seg].px;
      if (entry == 0) px.insert(px.end(), p.begin(), p.end());
      else px.insert(px.end(), p.rbegin(), p.rend());
      const int exit_end = 2 * seg + (1 - entry);
      const int next = link[exit_end];
      if (next < 0) break;
      cv::LineIterator it(end_px(exit_end), end_px(next), 8);
      for (int k = 0; k < it.count; ++k, ++it)
        if (k > 0 && k + 1 < it.count) px.push_back(it.pos());
      if (used[next / 2]) break;  // back at the start: a closed chain
      seg = next / 2;
      entry = next % 2;
    }
    SkeletonBranch b;
    b.pixels.reserve(px.size());
    for (const cv::Point& p : px) b.pixels.emplace_back(static_cast<float>(p.x - 2), static_cast<float>(p.y - 2));
    out.push_back(std::move(b));
  };
  for (int i = 1; i < n_segs; ++i) {
    if (segs[i].dropped || used[i] || segs[i].closed) continue;
    if (link[2 * i] < 0) emit(i, 0);
    else if (link[2 * i + 1] < 0) emit(i, 1);
  }
  for (int i = 1; i < n_segs; ++i)  // rings and closed chains
    if (!segs[i].dropped && !used[i]) emit(i, 0);
  return out;
}

}  // namespace

std::vector<SkeletonBranch> skeleton_branches(const cv::Mat1b& mask_in, double min_branch_px) {
  if (mask_in.empty()) return {};
  cv::Mat1f dist;
  cv::Mat1b padded;
  cv::copyMakeBorder(mask_in > 0, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
  cv::distanceTransform(padded, dist, cv::DIST_L2, 3);
  double max_half_width = 0;
  cv::minMaxLoc(dist, nullptr, &max_half_width);
  // Thinning time grows with the stroke's half width (one iteration per pixel peeled) times
  // the box's area. A wide stroke (typical half width over 8 px: twice the mean distance to
  // the background, as for a uniform stripe) is thinned at 1/f scale, typical half width 4 to
  // 8 px there; a cell is set when most of its pixels are (a cell set by any pixel makes
  // staircase diagonals two cells thick, which Zhang-Suen erases entirely). Parts narrower
  // than about f pixels vanish at that scale, and branches are placed to about f / 2 pixels.
  const double typical_half_width = 2 * cv::mean(dist, padded)[0];
  const int f = typical_half_width > 8 ? static_cast<int>(typical_half_width / 4) : 1;
  if (f == 1) return branches_of(mask_in, min_branch_px, max_half_width, &padded, &dist);
  const int w = (mask_in.cols + f - 1) / f, h = (mask_in.rows + f - 1) / f;
  cv::Mat1b big(h * f, w * f, uchar(0)), small;
  cv::Mat1b(mask_in > 0).copyTo(big(cv::Rect(0, 0, mask_in.cols, mask_in.rows)));
  cv::resize(big, small, {w, h}, 0, 0, cv::INTER_AREA);
  small = small >= 128;
  std::vector<SkeletonBranch> coarse = branches_of(small, min_branch_px / f, max_half_width / f + 1);
  // Back to full resolution: cell centres joined by 8-connected pixel lines.
  std::vector<SkeletonBranch> out;
  out.reserve(coarse.size());
  const float half = (f - 1) / 2.0f;
  const cv::Rect bounds(0, 0, mask_in.cols, mask_in.rows);
  for (const SkeletonBranch& c : coarse) {
    const bool closed = is_closed(c);
    std::vector<cv::Point> pts;
    for (const cv::Point2f& p : c.pixels) {
      cv::Point q(cvRound(p.x * f + half), cvRound(p.y * f + half));
      q.x = std::min(q.x, mask_in.cols - 1), q.y = std::min(q.y, mask_in.rows - 1);
      pts.push_back(q);
    }
    if (closed) pts.push_back(pts.front());
    SkeletonBranch b;
    for (size_t i = 0; i < pts.size(); ++i) {
      if (i == 0) {
        b.pixels.emplace_back(pts[0]);
        continue;
      }
      cv::LineIterator it(pts[i - 1], pts[i], 8);
      for (int k = 0; k < it.count; ++k, ++it)
        if (k > 0 && bounds.contains(it.pos())) b.pixels.emplace_back(it.pos());
    }
    if (closed && b.pixels.size() > 1) b.pixels.pop_back();  // the start again
    out.push_back(std::move(b));
  }
  return out;
}

// ---- B-spline ---------------------------------------------------------------------------
namespace {

void basis(double f, double b[4], double d[4]) {
  const double f2 = f * f, f3 = f2 * f;
  b[0] = (1 - f) * (1 - f) * (1 - f) / 6;
  b[1] = (3 * f3 - 6 * f2 + 4) / 6;
  b[2] = (-3 * f3 + 3 * f2 + 3 * f + 1) / 6;
  b[3] = f3 / 6;
  d[0] = -(1 - f) * (1 - f) / 2;
  d[1] = (9 * f2 - 12 * f) / 6;
  d[2] = (-9 * f2 + 6 * f + 3) / 6;
  d[3] = f2 / 2;
}

}  // namespace

SampledCurve fit_bspline(const SkeletonBranch& branch, double step_px, double extend_px) {
  SampledCurve out;
  const auto& pts = branch.pixels;
  if (pts.empty()) return out;
  if (pts.size() == 1 || step_px <= 0) {
    out.points.push_back(pts[0]);
    out.tangents.emplace_back(1.f, 0.f);
    return out;
  }
  const bool closed = is_closed(branch);
  const int n = static_cast<int>(pts.size());
  std::vector<double> t(n, 0.0);
  for (int i = 1; i < n; ++i) t[i] = t[i - 1] + cv::norm(pts[i] - pts[i - 1]);
  const double total = t[n - 1] + (closed ? cv::norm(pts[0] - pts[n - 1]) : 0.0);
  if (total <= 0) {
    out.points.push_back(pts[0]);
    out.tangents.emplace_back(1.f, 0.f);
    return out;
  }
  // Control points about every 8 px (at most ~200 of them): smooths the thinning's
  // staircase while following a stroke's bends.
  const double spacing = std::max(8.0, total / 200.0);
  const int spans = std::max(closed ? 4 : 1, static_cast<int>(std::lround(total / spacing)));
  const int nc = closed ? spans : spans + 3;
  auto ctrl_index = [&](int s, int k) { return closed ? (s + k) % nc : s + k; };
  auto locate = [&](double u, int& s, double& f) {
    s = std::clamp(static_cast<int>(std::floor(u)), 0, spans - 1);
    f = u - s;
  };

  cv::Mat1d M(nc, nc, 0.0), R(nc, 2, 0.0);
  double b[4], d[4];
  for (int i = 0; i < n; ++i) {
    const double u = t[i] / total * spans;
    int s;
    double f;
    locate(u, s, f);
    basis(f, b, d);
    for (int k = 0; k < 4; ++k) {
      const int r = ctrl_index(s, k);
      R(r, 0) += b[k] * pts[i].x;
      R(r, 1) += b[k] * pts[i].y;
      for (int l = 0; l < 4; ++l) M(r, ctrl_index(s, l)) += b[k] * b[l];
    }
  }
  // Light second-difference penalty: keeps spans without data well defined.
  const double lambda = 1e-2;
  for (int i = 0; i < nc; ++i) {
    if (!closed && (i == 0 || i == nc - 1)) continue;
    const int a = (i - 1 + nc) % nc, c = (i + 1) % nc;
    const int idx[3] = {a, i, c};
    const double w[3] = {1, -2, 1};
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) M(idx[k], idx[l]) += lambda * w[k] * w[l];
  }
  cv::Mat1d C;
  if (!cv::solve(M, R, C, cv::DECOMP_CHOLESKY)) cv::solve(M, R, C, cv::DECOMP_SVD);

  // Dense evaluation (about 4 samples per pixel of length), arc length, resampling.
  const int dense = std::max(8, static_cast<int>(std::ceil(total * 4)));
  std::vector<cv::Point2d> P(dense + 1), D(dense + 1);
  std::vector<double> arc(dense + 1, 0.0);
  for (int j = 0; j <= dense; ++j) {
    const double u = static_cast<double>(j) / dense * spans;
    int s;
    double f;
    locate(u, s, f);
    basis(f, b, d);
    cv::Point2d p(0, 0), q(0, 0);
    for (int k = 0; k < 4; ++k) {
      const int r = ctrl_index(s, k);
      p += cv::Point2d(C(r, 0), C(r, 1)) * b[k];
      q += cv::Point2d(C(r, 0), C(r, 1)) * d[k];
    }
    P[j] = p;
    D[j] = q;
    if (j > 0) arc[j] = arc[j - 1] + cv::norm(P[j] - P[j - 1]);
  }
  auto unit = [](cv::Point2d v, cv::Point2d fallback) {
    const double l = cv::norm(v);
    return l > 1e-9 ? v * (1.0 / l) : fallback;
  };
  std::vector<cv::Point2f> points, tangents;
  cv::Point2d last_t(1, 0);
  int j = 0;
  for (double s = 0; s <= arc[dense] + 1e-9; s += step_px) {
    if (closed && s > arc[dense] - 0.5 * step_px && !points.empty()) break;
    while (j + 1 < dense && arc[j + 1] < s) ++j;
    const double seg = arc[j + 1] - arc[j];
    const double w = seg > 0 ? std::clamp((s - arc[j]) / seg, 0.0, 1.0) : 0.0;
    const cv::Point2d p = P[j] * (1 - w) + P[j + 1] * w;
    last_t = unit(D[j] * (1 - w) + D[j + 1] * w, last_t);
    points.emplace_back(p);
    tangents.emplace_back(last_t);
  }
  if (!closed && extend_px > 0 && !points.empty()) {
    const int k = static_cast<int>(std::ceil(extend_px / step_px - 1e-9));
    const cv::Point2f t0 = tangents.front(), t1 = tangents.back();
    const cv::Point2f p0 = points.front(), p1 = points.back();
    for (int i = k; i >= 1; --i) {
      out.points.push_back(p0 - t0 * static_cast<float>(i * step_px));
      out.tangents.push_back(t0);
    }
    out.points.insert(out.points.end(), points.begin(), points.end());
    out.tangents.insert(out.tangents.end(), tangents.begin(), tangents.end());
    for (int i = 1; i <= k; ++i) {
      out.points.push_back(p1 + t1 * static_cast<float>(i * step_px));
      out.tangents.push_back(t1);
    }
    return out;
  }
  out.points = std::move(points);
  out.tangents = std::move(tangents);
  return out;
}

SkeletonBranch next_branch(const std::vector<SkeletonBranch>& branches, std::vector<bool>& done,
                           const cv::Point2f* from) {
  size_t best = 0;
  bool reverse = false;
  double best_d = 1e18;
  for (size_t i = 0; i < branches.size(); ++i) {
    if (done[i]) continue;
    const cv::Point2f here = from ? *from : branches[i].pixels.front();
    const double d0 = cv::norm(branches[i].pixels.front() - here), d1 = cv::norm(branches[i].pixels.back() - here);
    if (std::min(d0, d1) < best_d) {
      best_d = std::min(d0, d1);
      best = i;
      reverse = d1 < d0;
    }
  }
  done[best] = true;
  SkeletonBranch b = branches[best];
  if (reverse) std::reverse(b.pixels.begin(), b.pixels.end());
  return b;
}

}  // namespace atelier::embroidery
