#include "algorithms/pencil/texture.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <opencv2/core/hal/intrin.hpp>
#include <random>
#include <stdexcept>

namespace atelier::pencil {

namespace {

GreyRange grey_range(const std::vector<double>& hist, int from, int to) {
  GreyRange r;
  r.lo = std::clamp(std::min(from, to), 0, 255);
  r.hi = std::clamp(std::max(from, to), 0, 255);
  for (int v = r.lo; v <= r.hi; ++v) {
    r.total += hist[v];
    r.cdf[v - r.lo] = r.total;
  }
  // Both the bucket edges and the cdf rise: one walk finds each edge's upper bound.
  int i = 0;
  for (std::size_t k = 0; k < r.guide.size(); ++k) {
    const double edge = r.total * static_cast<double>(k) / r.guide.size();
    while (i <= r.hi - r.lo && r.cdf[i] <= edge) ++i;
    r.guide[k] = static_cast<std::uint16_t>(i);
  }
  return r;
}

// A uniform double in [0, 1) from one draw, exactly as std::generate_canonical<double, 53> makes
// it from a 64-bit engine (so results match std::uniform_real_distribution), without the
// logarithms libstdc++ works out on every call.
double canonical(std::mt19937_64& rng) {
  const double u = static_cast<double>(rng()) * 0x1p-64;
  return u < 1.0 ? u : std::nextafter(1.0, 0.0);
}

// A value of `range` from its quantile band [q0, q1] (0 = its darkest, 1 = its lightest); uniform
// over the range when its histogram is empty there.
inline int sample(const GreyRange& range, std::mt19937_64& rng, double q0 = 0.0, double q1 = 1.0) {
  const double u = canonical(rng) * (q1 - q0) + q0;
  const int span = range.hi - range.lo;
  if (range.total <= 0.0) return range.lo + std::min(span, static_cast<int>(u * (span + 1)));
  // The first i with cdf[i] > x (std::upper_bound), searched from the guide's start.
  const double x = u * range.total;
  const std::size_t k = std::min(range.guide.size() - 1, static_cast<std::size_t>(std::max(0.0, u) * range.guide.size()));
  int i = range.guide[k];
  while (i > 0 && range.cdf[i - 1] > x) --i;
  while (i <= span && range.cdf[i] <= x) ++i;
  return range.lo + std::min(i, span);
}

// The along-line neighbour offset for tangent (tx, ty), encoded (dx + 1) * 3 + (dy + 1): the
// direction is turned so that it maps to +y for a vertical line (the ccm's (p, q+1)).
std::uint8_t along_code(double tx, double ty) {
  if (std::abs(ty) >= std::abs(tx) ? ty < 0 : tx < 0) {
    tx = -tx;
    ty = -ty;
  }
  const double n = std::hypot(tx, ty);
  if (n == 0.0) return 1 * 3 + 2;  // a dot: straight down
  constexpr double kSin22 = 0.3826834;  // snap to the nearest of the 8 neighbours
  const int dx = tx / n > kSin22 ? 1 : (tx / n < -kSin22 ? -1 : 0);
  const int dy = ty / n > kSin22 ? 1 : (ty / n < -kSin22 ? -1 : 0);
  return static_cast<std::uint8_t>((dx + 1) * 3 + (dy + 1));
}

// One chord of the path and the pixels (region coordinates) that may lie within the half width
// of it: its ends' box grown by the half width.
struct Chord {
  cv::Point2d a, ab;
  double inv_len2;
  std::uint8_t code;
  int x0, x1, y0, y1;
};

struct LinePixel {
  int x, y, cell;
};

// The points within `r` of a chord a -> a + ab lie in its rectangle grown by r at both ends:
// -r |ab| <= ab . p <= |ab|^2 + r |ab| and |n . p| <= r |ab| (p relative to a, n = (-ab.y, ab.x)).
// On a row that is an interval of x, linear in the row's y, with no square roots per row.
struct Strip {
  // Per constraint lo <= coef x + k py <= hi: x in [(lo - k py) / coef, (hi - k py) / coef].
  std::array<double, 2> inv{}, k{}, lo{}, hi{};
  bool empty = false;  // a dot: no rectangle (its box is all there is)

  Strip(cv::Point2d ab, double r) {
    const double len2 = ab.dot(ab), reach = r * std::sqrt(len2);
    const std::array<double, 2> coef{ab.x, -ab.y};
    k = {ab.y, ab.x};
    lo = {-reach, -reach};
    hi = {len2 + reach, reach};
    empty = len2 == 0.0;
    for (int i = 0; i < 2; ++i) inv[i] = coef[i] != 0.0 ? 1.0 / coef[i] : 0.0;
  }

  // The row py's x range [from, to] (relative to a); false when the row misses the strip.
  bool row(double py, double& from, double& to) const {
    from = -std::numeric_limits<double>::infinity(), to = -from;
    if (empty) return true;
    for (int i = 0; i < 2; ++i) {
      const double offset = k[i] * py;
      if (inv[i] == 0.0) {  // the constraint does not depend on x
        if (offset < lo[i] || offset > hi[i]) return false;
        continue;
      }
      double x1 = (lo[i] - offset) * inv[i], x2 = (hi[i] - offset) * inv[i];
      if (inv[i] < 0.0) std::swap(x1, x2);
      from = std::max(from, x1), to = std::min(to, x2);
    }
    return from <= to;
  }
};

// Rounding slack (px) for a strip's rows: a pixel the distance test takes as within the half
// width must not fall outside them.
constexpr double kSlackPx = 1e-4;

// Everything of a PreparedProfile but the ccm table: cheap enough to make for a single line.
PreparedProfile prepare_zones(const PencilProfile& profile) {
  if (profile.mid_hist.size() != 256 || profile.hist.size() != 256 || profile.ccm.size() != 256 * 256)
    throw std::invalid_argument("draw_pencil_line: profile needs 256-bin histograms and a 256 x 256 ccm");
  PreparedProfile pp;
  pp.half = std::max(0.5, profile.width_px / 2.0);
  // The near zone is as wide as the profile's share of dark pixels ([min_range, max_mid]) asks:
  // of the ~width_px pixels across the line, that share is dark, one of them the centre.
  double dark = 0.0;
  for (int v = std::max(0, profile.min_range); v <= std::min(255, profile.max_mid); ++v) dark += profile.hist[v];
  pp.inner = std::clamp(0.5 + (dark * 2.0 * pp.half - 1.0) / 2.0, 0.5, pp.half);
  pp.centre = grey_range(profile.mid_hist, profile.min_mid, profile.max_mid);
  pp.near = grey_range(profile.hist, profile.min_range, profile.max_mid);
  pp.far = grey_range(profile.hist, profile.max_mid, profile.max_range);
  pp.zone_lo = {0, profile.min_mid, profile.min_range, profile.max_mid};
  pp.zone_hi = {255, profile.max_mid, profile.max_mid, profile.max_range};
  return pp;
}

// The line, with `occurs(i, j)` telling whether the ccm pair (upper i, lower j) occurs.
template <typename Occurs>
void draw_line(cv::Mat& canvas, const std::vector<cv::Point2d>& path, const PreparedProfile& pp, Occurs occurs,
               std::uint64_t seed) {
  if (path.empty() || canvas.empty()) return;

  const double half = pp.half, inner = pp.inner;
  // The region: the path's bounding box grown by the half width and the blur's reach.
  double x0 = path[0].x, x1 = x0, y0 = path[0].y, y1 = y0;
  for (const cv::Point2d& p : path) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y))
      throw std::invalid_argument("draw_pencil_line: non-finite path point");
    x0 = std::min(x0, p.x), x1 = std::max(x1, p.x);
    y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
  }
  const int margin = static_cast<int>(std::ceil(half)) + 2;
  const cv::Rect grown(static_cast<int>(std::floor(x0)) - margin, static_cast<int>(std::floor(y0)) - margin,
                       static_cast<int>(std::ceil(x1) - std::floor(x0)) + 2 * margin + 1,
                       static_cast<int>(std::ceil(y1) - std::floor(y0)) + 2 * margin + 1);
  const cv::Rect roi = grown & cv::Rect(0, 0, canvas.cols, canvas.rows);
  if (roi.empty()) return;
  const int width = roi.width, height = roi.height;

  // Chords through the path's samples: from each kept sample the farthest later one, at most
  // kMaxChordPx away, with every sample in between within kChordTolPx of the chord. Straight
  // stretches take few chords (the distance work below is per chord), tight turns are followed
  // (fixed 2 px chords cut the hooks at some lines' ends by up to a pixel).
  constexpr double kMaxChordPx = 6.0, kChordTolPx = 0.1;
  std::vector<cv::Point2d> pts;
  pts.reserve(path.size() / 4 + 2);
  pts.push_back(path.front());
  for (std::size_t a = 0; a + 1 < path.size();) {
    std::size_t b = a + 1;
    for (std::size_t c = b + 1; c < path.size(); b = c++) {
      const cv::Point2d ac = path[c] - path[a];
      const double len2 = ac.dot(ac);
      if (len2 > kMaxChordPx * kMaxChordPx) break;
      // The samples in the middle and next to c stand for all in between (the path is a smooth
      // spline: within a few pixels it bends one way, farthest from the chord in the middle).
      auto near_chord = [&](std::size_t m) {
        const cv::Point2d am = path[m] - path[a];
        const double across = ac.x * am.y - ac.y * am.x, along = ac.dot(am);
        return across * across <= kChordTolPx * kChordTolPx * len2 && along >= 0.0 && along <= len2;
      };
      if (!near_chord((a + c) / 2) || !near_chord(c - 1)) break;
    }
    pts.push_back(path[b]);
    a = b;
  }

  // The cells worked on, row by row (region coordinates): row y holds x in [lo[y], hi[y]], the
  // union of the chords' boxes grown by one pixel (so every 3x3 neighbour of a line pixel inside
  // the region is a cell), at cell base[y] + x. A diagonal line's bounding box is mostly empty;
  // this band is a few pixels wider than the line.
  const std::size_t segments = pts.size() == 1 ? 1 : pts.size() - 1;
  std::vector<Chord> chords;
  chords.reserve(segments);
  std::vector<int> lo(height, width), hi(height, -1), base(height, 0);
  for (std::size_t s = 0; s < segments; ++s) {
    const cv::Point2d a = pts[s], b = pts[std::min(s + 1, pts.size() - 1)];
    const cv::Point2d ab = b - a;
    const Chord c{a, ab, ab.dot(ab) > 0.0 ? 1.0 / ab.dot(ab) : 0.0, along_code(ab.x, ab.y),
                  std::max(roi.x, static_cast<int>(std::floor(std::min(a.x, b.x) - half))) - roi.x,
                  std::min(roi.x + width - 1, static_cast<int>(std::ceil(std::max(a.x, b.x) + half))) - roi.x,
                  std::max(roi.y, static_cast<int>(std::floor(std::min(a.y, b.y) - half))) - roi.y,
                  std::min(roi.y + height - 1, static_cast<int>(std::ceil(std::max(a.y, b.y) + half))) - roi.y};
    if (c.x0 > c.x1 || c.y0 > c.y1) continue;  // wholly off the canvas
    for (int y = std::max(0, c.y0 - 1); y <= std::min(height - 1, c.y1 + 1); ++y) {
      lo[y] = std::min(lo[y], std::max(0, c.x0 - 1));
      hi[y] = std::max(hi[y], std::min(width - 1, c.x1 + 1));
    }
    chords.push_back(c);
  }
  int cells = 0;
  for (int y = 0; y < height; ++y) {
    base[y] = cells - lo[y];
    cells += std::max(0, hi[y] - lo[y] + 1);
  }

  // Squared distance to the path and the along-line direction of the nearest chord, per cell.
  // In float, with 32-bit codes, so that four pixels go at a time; a pixel's distance is off by
  // ~1e-6 px at most, far below anything the zones or the texture can show.
  std::vector<float> dist(cells, 1e9f);
  std::vector<std::int32_t> along(cells, 0);  // every line pixel gets its nearest chord's code
  for (const Chord& c : chords) {
    const Strip strip(c.ab, half);
    const float abx = static_cast<float>(c.ab.x), aby = static_cast<float>(c.ab.y);
    const float inv_len2 = static_cast<float>(c.inv_len2), left = static_cast<float>(roi.x - c.a.x);
    const std::int32_t code = c.code;
    for (int y = c.y0; y <= c.y1; ++y) {
      float* drow = dist.data() + base[y];
      std::int32_t* arow = along.data() + base[y];
      const double py = y + roi.y - c.a.y;
      const float fy = static_cast<float>(py);
      // Only the pixels of this row within the half width of the chord can take it as their
      // nearest and be line (the others keep their distance, and no line pixel is missed).
      double from = 0, to = 0;
      if (!strip.row(py, from, to)) continue;
      // Region columns; floor and ceil by truncation (the plain build has no SSE4.1 rounding),
      // one column wider, which only evaluates a pixel more.
      const double first = std::max(c.a.x + from - kSlackPx - roi.x, -1.0);
      const double last = std::min(c.a.x + to + kSlackPx - roi.x, static_cast<double>(width));
      const int xa = std::max(c.x0, static_cast<int>(first) - 1);
      const int xb = std::min(c.x1, static_cast<int>(last) + 1);
      const float fy_aby = fy * aby;
      int x = xa;
#if CV_SIMD128
      // Four pixels at a time with OpenCV's universal intrinsics; selects, not branches (which
      // chord is nearer is a coin toss near the line). The same arithmetic as the scalar loop.
      const cv::v_float32x4 vabx = cv::v_setall_f32(abx), vaby = cv::v_setall_f32(aby);
      const cv::v_float32x4 vinv = cv::v_setall_f32(inv_len2), vfy = cv::v_setall_f32(fy);
      const cv::v_float32x4 vfy_aby = cv::v_setall_f32(fy_aby), zero = cv::v_setzero_f32();
      const cv::v_float32x4 one = cv::v_setall_f32(1.0f), steps(0.0f, 1.0f, 2.0f, 3.0f);
      const cv::v_int32x4 vcode = cv::v_setall_s32(code);
      for (; x + 3 <= xb; x += 4) {
        const cv::v_float32x4 px = (cv::v_setall_f32(static_cast<float>(x)) + steps) + cv::v_setall_f32(left);
        const cv::v_float32x4 t = cv::v_min(one, cv::v_max(zero, (px * vabx + vfy_aby) * vinv));
        const cv::v_float32x4 ex = px - t * vabx, ey = vfy - t * vaby;
        const cv::v_float32x4 d2 = ex * ex + ey * ey;
        const cv::v_float32x4 old = cv::v_load(drow + x);
        const cv::v_float32x4 nearer = d2 < old;
        cv::v_store(drow + x, cv::v_select(nearer, d2, old));
        cv::v_store(arow + x, cv::v_select(cv::v_reinterpret_as_s32(nearer), vcode, cv::v_load(arow + x)));
      }
#endif
      for (; x <= xb; ++x) {
        const float px = static_cast<float>(x) + left;
        const float t = std::min(1.0f, std::max(0.0f, (px * abx + fy_aby) * inv_len2));
        const float ex = px - t * abx, ey = fy - t * aby;
        const float d2 = ex * ex + ey * ey;
        if (d2 < drow[x]) drow[x] = d2, arow[x] = code;
      }
    }
  }

  // Seed: the bell-shaped fall-off, darkest at the centre.
  std::mt19937_64 rng(seed);
  // Within the two outer zones the fall-off continues: a pixel at fraction s of its zone's width
  // takes its value from the quantile band around s of the zone's range, so lines lighten
  // steadily outwards instead of jumping between dark and light (and the blur keeps the shades).
  // The band is about one pixel's share of its zone on each side of the line.
  auto band_of = [](double zone_px) { return std::clamp(0.5 / std::max(zone_px, 1e-9), 0.05, 0.5); };
  auto banded = [&rng](const GreyRange& range, double s, double b) {
    return sample(range, rng, std::min(1.0 - 2 * b, std::max(0.0, s - b)), std::min(1.0, std::max(2 * b, s + b)));
  };
  // zone: 0 paper, 1 centre, 2 near, 3 far (the zone decides the values a pixel may take).
  // Cells that are not line stay paper (255), which the blur reads.
  std::vector<std::uint8_t> val(cells, 255), zone(cells, 0);
  std::vector<LinePixel> pixels;  // the line's pixels in row-major order
  pixels.reserve(static_cast<std::size_t>(path.size() * 0.5 * (2.0 * half + 2.0)) + 16);
  const double near_px = inner - 0.5, far_px = half - inner;
  const double near_band = band_of(near_px), far_band = band_of(far_px);
  const float line_d2 = static_cast<float>(half * half);
  for (int y = 0; y < height; ++y) {
    for (int x = lo[y]; x <= hi[y]; ++x) {
      const int cell = base[y] + x;
      if (dist[cell] > line_d2) continue;
      const double d = std::sqrt(static_cast<double>(dist[cell]));
      pixels.push_back({x, y, cell});
      if (d <= 0.5) {
        zone[cell] = 1, val[cell] = static_cast<std::uint8_t>(sample(pp.centre, rng));
      } else if (d <= inner) {
        zone[cell] = 2, val[cell] = static_cast<std::uint8_t>(banded(pp.near, (d - 0.5) / std::max(1e-9, near_px), near_band));
      } else {
        zone[cell] = 3, val[cell] = static_cast<std::uint8_t>(banded(pp.far, (d - inner) / std::max(1e-9, far_px), far_band));
      }
    }
  }

  // CCM: a pixel whose pair with its along-line neighbour never occurs in the profile takes the
  // neighbouring value (3x3) nearest its own whose pairs, forward and backward (unless that one is
  // broken anyway), occur and that lies in the pixel's own zone range (so the fall-off across the
  // line survives). Pixels are visited in order, each pass over the whole line; a pixel is only
  // worked out again once something in its 3x3 neighbourhood (itself included) has changed since
  // it last was -- otherwise it would come to the same answer -- so the result is that of full
  // passes, and the passes stop when one changes nothing.
  // Out-of-region neighbours read a paper cell past the band's end (zone 0, value 255).
  const int paper = cells;
  val.push_back(255), zone.push_back(0);
  auto line_cell = [&](int x, int y) {  // the cell of a line pixel at (x, y), else `paper`
    if (x < 0 || y < 0 || x >= width || y >= height) return paper;
    const int c = base[y] + x;
    return zone[c] != 0 ? c : paper;
  };
  // Each pixel's along-line neighbours, forward (the ccm's lower pixel) and backward.
  constexpr std::array<int, 9> kDx{-1, -1, -1, 0, 0, 0, 1, 1, 1}, kDy{-1, 0, 1, -1, 0, 1, -1, 0, 1};
  std::vector<std::array<int, 2>> links(pixels.size());
  for (std::size_t k = 0; k < pixels.size(); ++k) {
    const LinePixel& p = pixels[k];
    const int code = along[p.cell];
    const int dx = kDx[code], dy = kDy[code];
    links[k] = {line_cell(p.x + dx, p.y + dy), line_cell(p.x - dx, p.y - dy)};
  }
  std::vector<std::uint8_t> dirty(cells + 1, 1);
  for (int pass = 0; pass < kMaxCcmPasses; ++pass) {
    int changes = 0;
    for (std::size_t k = 0; k < pixels.size(); ++k) {
      const LinePixel& p = pixels[k];
      if (!dirty[p.cell]) continue;
      dirty[p.cell] = 0;
      const auto [next_cell, prev_cell] = links[k];
      if (next_cell == paper) continue;
      const int v = val[p.cell], next = val[next_cell];
      if (occurs(v, next)) continue;
      const bool has_prev = prev_cell != paper;
      const int prev = val[prev_cell];
      const int zlo = pp.zone_lo[zone[p.cell]], zhi = pp.zone_hi[zone[p.cell]];
      // The 8 neighbours in scan order (rows top to bottom, each left to right).
      std::array<int, 8> around;
      const bool inside = p.x > 0 && p.y > 0 && p.x < width - 1 && p.y < height - 1;
      if (inside) {
        const int up = base[p.y - 1] + p.x, mid = p.cell, down = base[p.y + 1] + p.x;
        around = {up - 1, up, up + 1, mid - 1, mid + 1, down - 1, down, down + 1};
      } else {
        for (int i = 0, j = 0; i < 9; ++i)
          if (i != 4) around[j++] = line_cell(p.x + i % 3 - 1, p.y + i / 3 - 1);
      }
      // The nearest candidate, the first in scan order among equals: the least key
      // |c - v| << 16 | order << 8 | c (selects rather than branches: the tests are coin tosses).
      constexpr int kNone = 1 << 30;
      int best_key = kNone, relaxed_key = kNone;
      for (int order = 0; order < 8; ++order) {
        const int n = around[order];
        const int c = val[n];
        const int key = std::abs(c - v) << 16 | order << 8 | c;
        const bool fits = (zone[n] != 0) & (c >= zlo) & (c <= zhi) & occurs(c, next);
        relaxed_key = fits ? std::min(relaxed_key, key) : relaxed_key;
        best_key = fits & (!has_prev | occurs(prev, c)) ? std::min(best_key, key) : best_key;
      }
      const int best = best_key != kNone ? (best_key & 255) : -1;
      const int best_relaxed = relaxed_key != kNone ? (relaxed_key & 255) : -1;
      // The relaxed choice only where the backward pair is broken already: a change never adds
      // a broken pair, so the passes settle instead of pushing a break up and down the line.
      const bool back_broken = has_prev && !occurs(prev, v);
      const int chosen = best >= 0 ? best : (back_broken || !has_prev ? best_relaxed : -1);
      if (chosen >= 0 && chosen != v) {
        val[p.cell] = static_cast<std::uint8_t>(chosen);
        ++changes;
        // Its line neighbours are among `around` (the others, and `paper`, are never visited).
        dirty[p.cell] = 1;
        for (const int n : around) dirty[n] = 1;
      }
    }
    if (changes == 0) break;
  }

  // One 3x3 Gaussian pass on the line's pixels, then onto the canvas by min (graphite only
  // darkens). The pass is OpenCV's fixed-point one for 8-bit images (taps in 1/256, rounded once
  // at the end; the region's edge replicated), so it equals cv::GaussianBlur on the region.
  const double side = std::exp(-1.0 / (2.0 * kBlurSigma * kBlurSigma));
  const unsigned w_side = static_cast<unsigned>(std::lround(256.0 * side / (1.0 + 2.0 * side)));
  const unsigned w_mid = 256u - 2u * w_side;
  cv::Mat target = canvas(roi);
  for (const LinePixel& p : pixels) {
    const bool inside = p.x > 0 && p.y > 0 && p.x < width - 1 && p.y < height - 1;
    const int xl = inside ? p.x - 1 : std::max(0, p.x - 1), xr = inside ? p.x + 1 : std::min(width - 1, p.x + 1);
    const int yu = inside ? p.y - 1 : std::max(0, p.y - 1), yd = inside ? p.y + 1 : std::min(height - 1, p.y + 1);
    auto row = [&](int y) {
      const std::uint8_t* r = val.data() + base[y];
      return w_side * r[xl] + w_mid * r[p.x] + w_side * r[xr];
    };
    const unsigned sum = w_side * row(yu) + w_mid * row(p.y) + w_side * row(yd);
    std::uint8_t& c = target.at<std::uint8_t>(p.y, p.x);
    c = std::min(c, static_cast<std::uint8_t>((sum + (1u << 15)) >> 16));
  }
}

}  // namespace

PreparedProfile prepare(const PencilProfile& profile) {
  PreparedProfile pp = prepare_zones(profile);
  pp.ccm_occurs.assign(256 * 256, 0);
  for (std::size_t k = 0; k < profile.ccm.size(); ++k)
    pp.ccm_occurs[k] = profile.ccm[k] > 0.0;
  return pp;
}

void draw_pencil_line(cv::Mat& canvas, const std::vector<cv::Point2d>& path, const PencilProfile& profile,
                      std::uint64_t seed) {
  if (canvas.type() != CV_8UC1) throw std::invalid_argument("draw_pencil_line: canvas must be CV_8UC1");
  // One line reads the few ccm cells it needs rather than all 512 KB of them into a table.
  const PreparedProfile pp = prepare_zones(profile);
  const double* ccm = profile.ccm.data();
  draw_line(canvas, path, pp, [ccm](int i, int j) { return ccm[i * 256 + j] > 0.0; }, seed);
}

void draw_pencil_line(cv::Mat& canvas, const std::vector<cv::Point2d>& path, const PreparedProfile& profile,
                      std::uint64_t seed) {
  if (canvas.type() != CV_8UC1) throw std::invalid_argument("draw_pencil_line: canvas must be CV_8UC1");
  if (profile.ccm_occurs.size() != 256 * 256)
    throw std::invalid_argument("draw_pencil_line: the profile was not made by prepare()");
  draw_line(canvas, path, profile, [&profile](int i, int j) { return profile.occurs(i, j); }, seed);
}

}  // namespace atelier::pencil
