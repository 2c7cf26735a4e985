// Procedural stitch tiles: each pixel is shaded from the thread it lies on (a cylinder across
// the thread, a twist pattern along it, a sheen) and, for long-short and edge, the seam where
// one stitch ends and the next begins. Normals come from the same geometry.
#include "algorithms/embroidery/textures.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace atelier::embroidery {
namespace {

constexpr double kPxPerMm = 32;   // tile resolution
constexpr double kPi = 3.14159265358979323846;

// Deterministic per-thread jitter in [-1, 1] (no global RNG: textures are reproducible).
double jitter(int i, int salt) {
  std::uint32_t h = static_cast<std::uint32_t>(i) * 2654435761u ^ static_cast<std::uint32_t>(salt) * 40503u;
  h ^= h >> 15;
  h *= 2246822519u;
  h ^= h >> 13;
  return (h % 20001) / 10000.0 - 1.0;
}

struct Texel {
  double brightness = 0;   // 0..1 of the reference colour's white
  double alpha = 1;        // 0 = seam
  double nu = 0, nv = 0, nz = 1;   // tile-frame normal (v down), not yet normalised
};

ReferenceTexture make_tile(double width_mm, double height_mm, Texel (*shade)(double x, double y, int w, int h)) {
  const int w = static_cast<int>(std::lround(width_mm * kPxPerMm));
  const int h = static_cast<int>(std::lround(height_mm * kPxPerMm));
  ReferenceTexture t;
  t.width_mm = width_mm;
  t.height_mm = height_mm;
  t.color.create(h, w);
  t.alpha.create(h, w);
  t.normal.create(h, w);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Texel s = shade(x + 0.5, y + 0.5, w, h);
      const auto g = cv::saturate_cast<uchar>(255.0 * std::clamp(s.brightness, 0.0, 1.0));
      // A warm light grey reference thread; recolouring maps its mean to the region colour.
      t.color(y, x) = cv::Vec3b(cv::saturate_cast<uchar>(g * 0.94), g, g);
      t.alpha(y, x) = cv::saturate_cast<uchar>(255.0 * std::clamp(s.alpha, 0.0, 1.0));
      const double n = std::sqrt(s.nu * s.nu + s.nv * s.nv + s.nz * s.nz);
      const double nu = s.nu / n, nv = s.nv / n, nz = s.nz / n;
      // OpenGL convention: R = +u, G = up = -v, B = out; stored B,G,R.
      t.normal(y, x) = cv::Vec3b(cv::saturate_cast<uchar>((nz + 1) * 127.5),
                                 cv::saturate_cast<uchar>((-nv + 1) * 127.5),
                                 cv::saturate_cast<uchar>((nu + 1) * 127.5));
    }
  return t;
}

// Cross-section of a round thread: t in [-1, 1] across it; returns height in [0, 1].
double bulge(double t) { return std::sqrt(std::max(0.0, 1.0 - t * t)); }

// Light from the top-left: a sheen just above the thread's crest.
double sheen(double t, double width) { return std::exp(-((t + 0.3) / width) * ((t + 0.3) / width)); }

Texel long_short_texel(double x, double y, int w, int h) {
  const double pitch = h / 10.0;        // ten 0.3 mm threads per 3 mm row
  const int j = static_cast<int>(std::floor(y / pitch));
  const double t = 2.0 * (y / pitch - j) - 1.0;
  const double period = w / 2.0;        // 4 mm stitches; the centre half is one period
  // Long and short stitches: neighbouring threads end 2 mm apart, with a little jitter.
  const double offset = period * ((j % 2 == 0 ? 0.22 : 0.72) + 0.12 * jitter(j, 1));
  double d = std::fmod(x - offset, period);
  if (d < 0) d += period;
  const double to_seam = std::min(d, period - d);             // px to the nearest stitch end
  const double to_end = std::min(x, w - x);                   // the row's clean ends
  const double gap = 0.02 * kPxPerMm;   // half width of a seam (the next stitch shares the hole)
  const double dive = 0.25 * kPxPerMm;                        // thread sinks into the fabric
  Texel s;
  const double hgt = bulge(t);
  const double twist = 0.5 + 0.5 * std::cos(2 * kPi * (x / (1.0 * kPxPerMm) + 0.35 * t));
  const double sink = std::min({1.0, to_seam / dive, to_end / dive + 0.3});
  s.brightness = (0.16 + 0.66 * hgt * (0.92 + 0.08 * twist) + 0.22 * sheen(t, 0.35)) * (0.8 + 0.2 * sink);
  s.alpha = to_seam < gap ? 0.0 : (to_seam < gap + 1.0 ? to_seam - gap : 1.0);
  // Rising out of the hole behind a seam, sinking into the next one: the normal leans back.
  const double slope = (1.0 - std::min(1.0, to_seam / dive)) * 0.8;
  s.nu = (d < period - d ? -slope : slope) + 0.1 * std::sin(2 * kPi * (x / (1.0 * kPxPerMm) + 0.35 * t));
  s.nv = t;
  s.nz = std::max(0.15, hgt);
  return s;
}

Texel satin_texel(double x, double y, int w, int h) {
  const double pitch = h / 3.0;         // three 0.4 mm threads (Ink/Stitch satin spacing)
  const int j = static_cast<int>(std::floor(y / pitch));
  const double t = 2.0 * (y / pitch - j) - 1.0;
  const double u = x / w;
  const double to_end = std::min(u, 1.0 - u);                 // the column's contour
  Texel s;
  const double hgt = bulge(t);
  // A satin column is domed (threads pulled over the column): bright crest, darker sides, and
  // a sheen just before the crest. This survives when the threads themselves are sub-pixel.
  const double dome = std::sin(kPi * u);
  const double crest = std::exp(-((u - 0.4) / 0.18) * ((u - 0.4) / 0.18));
  const double slow = 0.9 + 0.1 * std::cos(2 * kPi * (u * 1.5 + 0.3 * jitter(j, 2)));
  const double sink = std::min(1.0, to_end / 0.06 + 0.35);
  s.brightness = (0.25 + 0.40 * hgt * (0.55 + 0.45 * dome) + 0.30 * crest * (0.6 + 0.4 * hgt) * slow) *
                 (0.6 + 0.4 * sink);
  const double slope = (1.0 - std::min(1.0, to_end / 0.06)) * 0.7;
  s.nu = (u < 0.5 ? -slope : slope) - 0.5 * std::cos(kPi * u);
  s.nv = t;
  s.nz = std::max(0.15, hgt);
  return s;
}

Texel edge_texel(double x, double y, int w, int h) {
  const double angle = 35.0 * kPi / 180.0;   // stitches slanted 35 deg from the stroke
  const double spacing = w / 6.0;            // six stitches per 2 mm
  const double along = x - y / std::tan(angle);
  const int j = static_cast<int>(std::floor(along / spacing));
  const double t = 2.0 * (along / spacing - j) - 1.0;
  const double to_end = std::min(y, h - y) / h;              // stitch ends at the stroke's sides
  Texel s;
  const double hgt = bulge(t);
  const double sink = std::min(1.0, to_end / 0.15 + 0.3);
  s.brightness = (0.30 + 0.50 * hgt + 0.25 * sheen(t, 0.35)) * (0.6 + 0.4 * sink);
  s.alpha = std::abs(t) > 0.9 ? 0.0 : 1.0;   // a small gap between stitches
  // Across the slanted thread is (sin a, -cos a) in the tile frame.
  s.nu = t * std::sin(angle);
  s.nv = -t * std::cos(angle) + (y < h / 2.0 ? -1 : 1) * (1.0 - std::min(1.0, to_end / 0.15)) * 0.6;
  s.nz = std::max(0.15, hgt);
  return s;
}

}  // namespace

TextureSet procedural_textures() {
  TextureSet set;
  set.style[static_cast<int>(Style::long_short)] = make_tile(8.0, 3.0, long_short_texel);
  set.style[static_cast<int>(Style::satin)] = make_tile(4.0, 1.2, satin_texel);
  set.style[static_cast<int>(Style::edge)] = make_tile(2.0, 1.0, edge_texel);
  return set;
}

void validate_texture(const ReferenceTexture& t) {
  if (t.color.empty()) throw std::invalid_argument("reference texture: the colour image is empty");
  if (t.alpha.size() != t.color.size())
    throw std::invalid_argument("reference texture: the alpha image's size differs from the colour image's");
  if (t.normal.size() != t.color.size())
    throw std::invalid_argument("reference texture: the normal map's size differs from the colour image's");
  if (!(std::isfinite(t.width_mm) && t.width_mm > 0))
    throw std::invalid_argument("reference texture: width_mm must be positive, got " + std::to_string(t.width_mm));
  if (!(std::isfinite(t.height_mm) && t.height_mm > 0))
    throw std::invalid_argument("reference texture: height_mm must be positive, got " + std::to_string(t.height_mm));
}

}  // namespace atelier::embroidery
