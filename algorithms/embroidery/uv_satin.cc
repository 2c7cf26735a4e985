#include "algorithms/embroidery/uv_satin.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <vector>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/embroidery/skeleton.h"
#include "algorithms/embroidery/uv_long_short.h"

namespace atelier::embroidery {
namespace {

struct Sample {
  int branch;
  int k;   // index along the branch's curve
};

}  // namespace

std::vector<SatinPair> pair_satin_sides(const std::vector<SatinContourPx>& A, const std::vector<SatinContourPx>& B,
                                        double tile_h_px) {
  std::vector<SatinPair> pairs;
  if (!(tile_h_px > 0) || !std::isfinite(tile_h_px)) return pairs;
  // Every pixel's piece is its own integer, from one division; a piece gathers the pixels
  // whose index is at most the current one. Comparing s with a piece end rounded to float
  // instead stalled when a pixel's s equalled that rounded end (issue 21: a hang): here the
  // pixel at the minimum always belongs to the current piece, so each pass takes at least one
  // pixel and the loop ends after at most |A| + |B| passes.
  auto piece_of = [&](float s) {
    const double q = std::floor(static_cast<double>(s) / tile_h_px);
    return std::isfinite(q) ? static_cast<long long>(std::clamp(q, -1e15, 1e15)) : 0LL;
  };
  size_t ia = 0, ib = 0;
  while (ia < A.size() || ib < B.size()) {
    long long piece;
    if (ia < A.size() && ib < B.size()) piece = std::min(piece_of(A[ia].s), piece_of(B[ib].s));
    else piece = ia < A.size() ? piece_of(A[ia].s) : piece_of(B[ib].s);
    size_t ja = ia, jb = ib;
    while (ja < A.size() && piece_of(A[ja].s) <= piece) ++ja;
    while (jb < B.size() && piece_of(B[jb].s) <= piece) ++jb;
    const size_t na = ja - ia, nbb = jb - ib, m = std::max(na, nbb);
    if (na > 0 && nbb > 0)
      for (size_t i = 0; i < m; ++i) {   // one-to-many when the sides differ
        const double f = (i + 0.5) / m;
        const SatinContourPx& a = A[ia + std::min(na - 1, static_cast<size_t>(f * na))];
        const SatinContourPx& c = B[ib + std::min(nbb - 1, static_cast<size_t>(f * nbb))];
        const cv::Point2f e = c.p - a.p;
        const float len = std::sqrt(e.dot(e));
        pairs.push_back({a.p, c.p, 0.5f * (a.s + c.s), static_cast<float>(static_cast<double>(piece) + f), e, len,
                         len > 1e-6f ? 1.f / (len * len) : 0.f});
      }
    ia = ja;
    ib = jb;
  }
  return pairs;
}

RegionUV uv_satin(const cv::Mat1b& mask, const cv::Rect& box, double tile_w_px, double tile_h_px,
                  double direction) {
  const double step = 1.0;
  cv::Mat1f dt;
  cv::distanceTransform(mask, dt, cv::DIST_L2, cv::DIST_MASK_5);
  double max_dt = 0;
  cv::minMaxLoc(dt, nullptr, &max_dt);
  const double width = 2 * max_dt;
  const std::vector<SkeletonBranch> branches = skeleton_branches(mask, std::max(4.0, 0.5 * width));
  if (branches.empty()) return uv_long_short(mask, box, direction, tile_w_px, tile_h_px);

  // 1-3: curves, and every pixel's nearest curve sample (its branch = its sub-region).
  std::vector<SampledCurve> curves;
  std::vector<cv::Point2f> pts;
  std::vector<Sample> owner;
  for (int b = 0; b < static_cast<int>(branches.size()); ++b) {
    curves.push_back(fit_bspline(branches[b], step, 0.5 * width + 2));
    for (int k = 0; k < static_cast<int>(curves[b].points.size()); ++k) {
      pts.push_back(curves[b].points[k]);
      owner.push_back({b, k});
    }
  }
  const cv::Mat1i nearest = nearest_point_index(mask.size(), pts);
  if (pts.empty() || nearest(0, 0) < 0) return uv_long_short(mask, box, direction, tile_w_px, tile_h_px);

  // Foot point and side of a pixel on its branch's curve.
  auto foot = [&](int x, int y, int* branch, float* s, float* d, cv::Point2f* tangent) {
    const Sample smp = owner[nearest(y, x)];
    const SampledCurve& c = curves[smp.branch];
    // The distance transform's neighbour is approximate: look a few samples either way.
    const cv::Point2f p(static_cast<float>(x), static_cast<float>(y));
    int k = smp.k;
    float best = 1e30f;
    for (int j = std::max(0, smp.k - 3); j <= std::min<int>(c.points.size() - 1, smp.k + 3); ++j) {
      const cv::Point2f q = p - c.points[j];
      const float dd = q.dot(q);
      if (dd < best) best = dd, k = j;
    }
    const cv::Point2f q = p - c.points[k];
    const cv::Point2f t = c.tangents[k];
    *branch = smp.branch;
    *s = static_cast<float>(k * step) + q.dot(t);
    *d = t.x * q.y - t.y * q.x;
    *tangent = t;
  };

  // 4: contour pixels of each sub-region (the region contour, completed by the split between
  // sub-regions), per side, ordered by foot point.
  const int nb = static_cast<int>(branches.size());
  std::vector<std::vector<SatinContourPx>> side[2];
  side[0].resize(nb);
  side[1].resize(nb);
  cv::Mat1i branch_of(mask.size(), -1);
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x)
      if (mask(y, x)) branch_of(y, x) = owner[nearest(y, x)].branch;
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x) {
      const int b = branch_of(y, x);
      if (b < 0) continue;
      bool contour = false;
      static const int kDx[4] = {1, -1, 0, 0}, kDy[4] = {0, 0, 1, -1};
      for (int i = 0; i < 4 && !contour; ++i) {
        const int xx = x + kDx[i], yy = y + kDy[i];
        contour = xx < 0 || yy < 0 || xx >= mask.cols || yy >= mask.rows || branch_of(yy, xx) != b;
      }
      if (!contour) continue;
      int bb;
      float s, d;
      cv::Point2f t;
      foot(x, y, &bb, &s, &d, &t);
      side[d > 0 ? 0 : 1][b].push_back({s, cv::Point2f(static_cast<float>(x), static_cast<float>(y))});
    }

  // 5: pieces one tile high along the curve; pairs by relative order within each piece.
  std::vector<std::vector<SatinPair>> pairs(nb);
  for (int b = 0; b < nb; ++b) {
    for (auto& sd : side) {
      std::stable_sort(sd[b].begin(), sd[b].end(), [](const SatinContourPx& a, const SatinContourPx& c) { return a.s < c.s; });
    }
    pairs[b] = pair_satin_sides(side[0][b], side[1][b], tile_h_px);
    std::stable_sort(pairs[b].begin(), pairs[b].end(), [](const SatinPair& a, const SatinPair& c) { return a.s_mid < c.s_mid; });
  }

  // 6: u along the pairs' lines, v from their order, blended with eq. 7.
  RegionUV out = region_uv_with_angles(box, mask, direction);
  const float window = static_cast<float>(std::max(3.0, 0.5 * tile_h_px));
  std::atomic<bool> missing{false};
  // Rows are independent (each pixel reads the pairs and writes itself only): a large region
  // is split into bands, so it does not keep one thread busy while the other idles (OpenCV
  // runs a parallel_for_ nested in the synthesis' one serially).
  auto rows = [&](const cv::Range& range) {
  cv::Point2f last_t(0, 0);
  float last_angle = std::atan2(-last_t.x, last_t.y);
  for (int y = range.start; y < range.end; ++y)
    for (int x = 0; x < mask.cols; ++x) {
      if (!mask(y, x)) continue;
      int b;
      float s, d;
      cv::Point2f t;
      foot(x, y, &b, &s, &d, &t);
      const auto& P = pairs[b];
      if (P.empty()) {
        missing = true;
        out.mask(y, x) = 0;
        continue;
      }
      const cv::Point2f p(static_cast<float>(x), static_cast<float>(y));
      auto lo = std::lower_bound(P.begin(), P.end(), s - window, [](const SatinPair& a, float v) { return a.s_mid < v; });
      double sw = 0, su = 0, sv = 0;
      auto pair_uv = [&](const SatinPair& q, double* u, double* dist) {
        const cv::Point2f r = p - q.c0;
        *u = q.len > 1e-6f ? std::clamp(r.dot(q.e) / (q.len * q.len), 0.f, 1.f) : 0.5;
        *dist = q.len > 1e-6f ? std::abs(q.e.x * r.y - q.e.y * r.x) / q.len : std::sqrt(r.dot(r));
      };
      for (auto it = lo; it != P.end() && it->s_mid <= s + window; ++it) {
        if (it->len < 1e-6f) continue;
        const cv::Point2f r0 = p - it->c0;
        // |cross| / len is the distance to the pair's line. (|p-c0| + |p-c1|) >= |c0-c1|, so
        // eq. 7 is below exp(-dist): lines farther than 8 px do not count (no division to
        // find out).
        const float cross = std::abs(it->e.x * r0.y - it->e.y * r0.x);
        if (cross > 8.f * it->len) continue;
        const cv::Point2f r1 = p - it->c1;
        // eq. 7: exp(-(|p-c0| + |p-c1|) * dist / len), dist / len = cross / len^2.
        const double w = std::exp(-(std::sqrt(r0.dot(r0)) + std::sqrt(r1.dot(r1))) * cross * it->inv_len2);
        const double u = std::clamp(r0.dot(it->e) * it->inv_len2, 0.f, 1.f);
        sw += w;
        su += w * u;
        sv += w * it->v;
      }
      double u, v;
      if (sw > 1e-12) {
        u = su / sw;
        v = sv / sw;
      } else {
        // No pair near the foot point (a piece with one side only): the nearest pair.
        auto it = lo == P.end() ? P.end() - 1 : lo;
        if (it != P.begin() && std::abs((it - 1)->s_mid - s) < std::abs(it->s_mid - s)) --it;
        double dist;
        pair_uv(*it, &u, &dist);
        v = it->v;
      }
      out.uv(y, x) = cv::Vec2f(static_cast<float>(u), static_cast<float>(v - std::floor(v)));
      // +u runs from the +normal side to the other: (t.y, -t.x); +v is then along the curve.
      if (t != last_t) last_t = t, last_angle = std::atan2(-t.x, t.y);   // neighbours share a sample
      out.angle(y, x) = last_angle;
    }
  };
  if (mask.total() > 40000) cv::parallel_for_(cv::Range(0, mask.rows), rows);
  else rows(cv::Range(0, mask.rows));
  if (missing) {
    // Sub-regions with no pair (a branch whose contour lies on one side only) take the
    // long-short map in the region's direction.
    cv::Mat1b rest = mask & ~out.mask;
    const RegionUV ls = uv_long_short(rest, box, direction, tile_w_px, tile_h_px);
    ls.uv.copyTo(out.uv, rest);
    out.angle.setTo(static_cast<float>(direction), rest);
    out.mask = mask.clone();
  }
  return out;
}

}  // namespace atelier::embroidery
