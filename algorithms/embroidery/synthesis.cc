#include "algorithms/embroidery/synthesis.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/embroidery/recolor.h"
#include "algorithms/embroidery/uv_edge.h"
#include "algorithms/embroidery/uv_long_short.h"
#include "algorithms/embroidery/uv_satin.h"

namespace atelier::embroidery {
namespace {

// One style's tile at the image's scale, converted once for all regions.
struct ScaledTile {
  cv::Mat3b color;
  cv::Mat3f lab;
  cv::Mat1b alpha;
  cv::Mat4f normal;   // decoded tile-frame normal (u, v-down, out, 0): four floats sample at once
  cv::Vec3f mean_lab;
  double w_px = 0, h_px = 0;   // tile size in image pixels
  bool wrap_u = false;         // edge tiles repeat along u; long-short and satin end at contours
};

ScaledTile scale_tile(const ReferenceTexture& t, Style style, double px_per_mm) {
  ScaledTile s;
  s.w_px = t.width_mm * px_per_mm;
  s.h_px = t.height_mm * px_per_mm;
  // Satin's u spans a whole column whatever its width, so its u resolution stays.
  const int w = style == Style::satin ? t.color.cols : std::max(2, static_cast<int>(std::lround(s.w_px)));
  const int h = std::max(2, static_cast<int>(std::lround(s.h_px)));
  const int interp = (w < t.color.cols || h < t.color.rows) ? cv::INTER_AREA : cv::INTER_LINEAR;
  cv::resize(t.color, s.color, cv::Size(w, h), 0, 0, interp);
  cv::resize(t.alpha, s.alpha, cv::Size(w, h), 0, 0, interp);
  cv::Mat3b n8;
  cv::resize(t.normal, n8, cv::Size(w, h), 0, 0, interp);
  s.normal.create(h, w);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const cv::Vec3b b = n8(y, x);   // B = out, G = up, R = +u
      cv::Vec3f n(b[2] / 127.5f - 1.f, -(b[1] / 127.5f - 1.f), b[0] / 127.5f - 1.f);
      const float len = std::sqrt(n.dot(n));
      if (len > 0) n /= len;
      s.normal(y, x) = len > 0 ? cv::Vec4f(n[0], n[1], n[2], 0) : cv::Vec4f(0, 0, 1, 0);
    }
  s.lab = to_lab(s.color);
  s.mean_lab = tile_mean_lab(s.color, s.alpha);
  s.wrap_u = style == Style::edge;
  return s;
}

// Bilinear sampling position in a tile: v always repeats, u repeats for edge tiles only.
struct Tap {
  int x0, x1, y0, y1;
  float fx, fy;
};
Tap tap(float u, float v, int w, int h, bool wrap_u) {
  // u, v are in [0, 1] (UV maps keep them there), so one step of wrapping is enough.
  Tap t;
  const float x = u * w - 0.5f, y = v * h - 0.5f;
  const float xf = std::floor(x), yf = std::floor(y);
  t.fx = x - xf;
  t.fy = y - yf;
  const int x0 = static_cast<int>(xf), y0 = static_cast<int>(yf);
  auto wrap = [](int i, int n) { return i < 0 ? i + n : i >= n ? i - n : i; };
  t.y0 = wrap(std::clamp(y0, -1, h), h);
  t.y1 = wrap(std::clamp(y0 + 1, -1, h), h);
  if (wrap_u) {
    t.x0 = wrap(std::clamp(x0, -1, w), w);
    t.x1 = wrap(std::clamp(x0 + 1, -1, w), w);
  } else {
    t.x0 = std::clamp(x0, 0, w - 1);
    t.x1 = std::clamp(x0 + 1, 0, w - 1);
  }
  return t;
}
// Bilinear sample of a four-float tile.
inline void lerp4(const cv::Mat4f& m, const Tap& t, float out[4]) {
  const float* a = m.ptr<float>(t.y0) + 4 * t.x0;
  const float* b = m.ptr<float>(t.y0) + 4 * t.x1;
  const float* c = m.ptr<float>(t.y1) + 4 * t.x0;
  const float* d = m.ptr<float>(t.y1) + 4 * t.x1;
  const float w00 = (1 - t.fx) * (1 - t.fy), w01 = t.fx * (1 - t.fy), w10 = (1 - t.fx) * t.fy, w11 = t.fx * t.fy;
  for (int k = 0; k < 4; ++k) out[k] = a[k] * w00 + b[k] * w01 + c[k] * w10 + d[k] * w11;
}

// One region ready to render: its UVs and its recoloured tile (B, G, R, alpha in 0..1).
struct Layer {
  RegionUV uv;
  cv::Mat4f color;
  const ScaledTile* tile = nullptr;
  Style style = Style::long_short;
};

Layer prepare_region(const Segmentation& seg, const Region& r, double direction, const ScaledTile& tile,
                     const SynthesisParams& p) {
  Layer L;
  L.style = r.style;
  L.tile = &tile;
  // The paper (5.5) merges the unsynthesized pixels inside a long-short region's inner contours
  // into it. Ours are the fabric no stitch covers (the planner fills the region, not its
  // holes), so they stay bare: the preview shows no thread where the machine sews none.
  const cv::Mat1b& mask = r.mask;
  // Dilate on a box grown by dilate_px and clipped to the image, so neighbours overlap (5.5).
  // Edges lie on top and overlap nothing, so they keep their width (dilated, a 0.8 mm stroke
  // looked 1.3 mm wide over a running stitch of 0.4 mm).
  const int d = r.style == Style::edge ? 0 : p.dilate_px;
  const cv::Rect grown(r.bbox.x - d, r.bbox.y - d, r.bbox.width + 2 * d, r.bbox.height + 2 * d);
  const cv::Rect box = grown & cv::Rect(0, 0, seg.size.width, seg.size.height);
  cv::Mat1b big(grown.size(), uchar(0));
  mask.copyTo(big(cv::Rect(d, d, mask.cols, mask.rows)));
  if (d > 0)
    cv::dilate(big, big, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * d + 1, 2 * d + 1)));
  cv::Mat1b m = big(cv::Rect(box.x - grown.x, box.y - grown.y, box.width, box.height)).clone();
  // Only into a neighbour, never onto the bare fabric around the design: no stitch goes there.
  if (d > 0) m &= seg.region_id(box) >= 0;
  switch (r.style) {
    case Style::long_short: L.uv = uv_long_short(m, box, direction, tile.w_px, tile.h_px); break;
    case Style::satin: L.uv = uv_satin(m, box, tile.w_px, tile.h_px, direction); break;
    case Style::edge: L.uv = uv_edge(m, box, tile.w_px, tile.h_px, direction); break;
  }
  const cv::Mat3b colored = recolor_tile(tile.lab, tile.alpha, tile.mean_lab, seg.palette.lab.at(r.color), p.max_L);
  L.color.create(colored.size());
  for (int y = 0; y < colored.rows; ++y)
    for (int x = 0; x < colored.cols; ++x) {
      const cv::Vec3b c = colored(y, x);
      L.color(y, x) = cv::Vec4f(c[0], c[1], c[2], tile.alpha(y, x) / 255.f);
    }
  return L;
}

Synthesis synthesize_impl(const Segmentation& seg, const std::vector<double>& directions, const TextureSet& textures,
                          const SynthesisParams& p) {
  if (!(p.px_per_mm > 0) || !std::isfinite(p.px_per_mm))
    throw std::invalid_argument("synthesis: px_per_mm must be positive");
  if (!(p.max_L > 0 && p.max_L <= 100)) throw std::invalid_argument("synthesis: max_L must be in (0, 100]");
  if (p.dilate_px < 0) throw std::invalid_argument("synthesis: dilate_px must not be negative");
  if (directions.size() != seg.regions.size())
    throw std::invalid_argument("synthesis: " + std::to_string(directions.size()) + " directions for " +
                                std::to_string(seg.regions.size()) + " regions");
  if (seg.region_id.size() != seg.size)
    throw std::invalid_argument("synthesis: the region_id image's size differs from the segmentation's");
  for (const Region& r : seg.regions) {
    if (r.color < 0 || r.color >= static_cast<int>(seg.palette.lab.size()))
      throw std::invalid_argument("synthesis: region " + std::to_string(r.id) + " has no palette colour");
    if (r.mask.size() != r.bbox.size() || (r.bbox & cv::Rect(0, 0, seg.size.width, seg.size.height)) != r.bbox)
      throw std::invalid_argument("synthesis: region " + std::to_string(r.id) + " has a bad box or mask");
  }
  ScaledTile tiles[kStyleCount];
  for (int s = 0; s < kStyleCount; ++s) {
    validate_texture(textures.style[s]);
    tiles[s] = scale_tile(textures.style[s], static_cast<Style>(s), p.px_per_mm);
  }

  const int n = static_cast<int>(seg.regions.size());
  // Costliest first (box area; satin and edge maps thin and fit curves, so they cost more per
  // pixel), one region per task, so a large region does not start last on one thread while
  // the other idles.
  std::vector<int> by_cost(n);
  std::vector<double> cost(n);
  for (int i = 0; i < n; ++i) {
    by_cost[i] = i;
    cost[i] = static_cast<double>(seg.regions[i].mask.total()) * (seg.regions[i].style == Style::long_short ? 1 : 4);
  }
  std::stable_sort(by_cost.begin(), by_cost.end(), [&](int a, int b) { return cost[a] > cost[b]; });
  std::vector<Layer> layers(n);
  cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& range) {
    for (int k = range.start; k < range.end; ++k) {
      const int i = by_cost[k];
      const Region& r = seg.regions[i];
      if (r.mask.empty() || r.area_px == 0) continue;
      layers[i] = prepare_region(seg, r, directions[i], tiles[static_cast<int>(r.style)], p);
    }
  });

  // Layers (5.5): long-short in the background, then satin, then edge on top; within a layer,
  // by region index. Alpha lets seams show what lies below.
  std::vector<int> order;
  for (int s = 0; s < kStyleCount; ++s)
    for (int i = 0; i < n; ++i)
      if (static_cast<int>(layers[i].style) == s && !layers[i].uv.mask.empty()) order.push_back(i);

  Synthesis out;
  out.preview.create(seg.size);
  out.normal.create(seg.size);
  out.uv.create(seg.size);
  out.style.create(seg.size);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // Composition in bands of rows: every band walks the layers in order, so bands are
  // independent and the result does not depend on the thread count.
  cv::parallel_for_(cv::Range(0, seg.size.height), [&](const cv::Range& rows) {
    const cv::Rect band(0, rows.start, seg.size.width, rows.end - rows.start);
    out.preview(band).setTo(p.fabric_bgr);
    out.uv(band).setTo(cv::Vec2f(nan, nan));
    out.style(band).setTo(0);
    cv::Mat3f normal(band.size(), cv::Vec3f(0, 0, 1));
    for (int i : order) {
      const Layer& L = layers[i];
      const cv::Rect b = L.uv.box;
      const int y0 = std::max(b.y, rows.start), y1 = std::min(b.y + b.height, rows.end);
      const uchar style = static_cast<uchar>(static_cast<int>(L.style) + 1);
      const ScaledTile& tile = *L.tile;
      const int tw = tile.color.cols, th = tile.color.rows;
      float last_angle = std::numeric_limits<float>::quiet_NaN(), ca = 1, sa = 0;
      for (int Y = y0; Y < y1; ++Y) {
        const int y = Y - b.y;
        const uchar* m = L.uv.mask.ptr<uchar>(y);
        const cv::Vec2f* uv = L.uv.uv.ptr<cv::Vec2f>(y);
        cv::Vec3b* o = out.preview.ptr<cv::Vec3b>(Y) + b.x;
        cv::Vec2f* ouv = out.uv.ptr<cv::Vec2f>(Y) + b.x;
        uchar* ost = out.style.ptr<uchar>(Y) + b.x;
        cv::Vec3f* on = normal.ptr<cv::Vec3f>(Y - rows.start) + b.x;
        for (int x = 0; x < b.width; ++x) {
          if (!m[x]) continue;
          ouv[x] = uv[x];
          ost[x] = style;
          const Tap t = tap(uv[x][0], uv[x][1], tw, th, tile.wrap_u);
          float c[4];
          lerp4(L.color, t, c);
          const float a = c[3];
          if (a <= 0) continue;
          for (int k = 0; k < 3; ++k) o[x][k] = cv::saturate_cast<uchar>(a * c[k] + (1 - a) * o[x][k]);
          // Tile normal (u, v, out) into the image frame: +u along the stitch angle, +v at
          // angle + 90 deg.
          const float ang = L.uv.angle_at(y, x);
          if (ang != last_angle) last_angle = ang, ca = std::cos(ang), sa = std::sin(ang);
          float nt[4];
          lerp4(tile.normal, t, nt);
          const cv::Vec3f img(nt[0] * ca - nt[1] * sa, nt[0] * sa + nt[1] * ca, nt[2]);
          on[x] = a * img + (1 - a) * on[x];
        }
      }
    }
    for (int Y = rows.start; Y < rows.end; ++Y) {
      const cv::Vec3f* nr = normal.ptr<cv::Vec3f>(Y - rows.start);
      cv::Vec3b* o = out.normal.ptr<cv::Vec3b>(Y);
      for (int x = 0; x < seg.size.width; ++x) {
        cv::Vec3f v = nr[x];
        const float len = std::sqrt(v.dot(v));
        v = len > 0 ? v / len : cv::Vec3f(0, 0, 1);
        // Image frame (x right, y down) to the OpenGL convention: G = up = -y. Stored B,G,R.
        o[x] = cv::Vec3b(cv::saturate_cast<uchar>((v[2] + 1) * 127.5f), cv::saturate_cast<uchar>((-v[1] + 1) * 127.5f),
                         cv::saturate_cast<uchar>((v[0] + 1) * 127.5f));
      }
    }
  }, 16);
  return out;
}
}  // namespace

Synthesis synthesize(const Segmentation& seg, const std::vector<double>& directions, const TextureSet& textures,
                     const SynthesisParams& p) {
  try {
    return synthesize_impl(seg, directions, textures, p);
  } catch (const cv::Exception& e) {
    // The algorithms boundary: callers see standard exceptions only.
    throw std::runtime_error(std::string("synthesis: OpenCV failed: ") + e.what());
  }
}

}  // namespace atelier::embroidery
