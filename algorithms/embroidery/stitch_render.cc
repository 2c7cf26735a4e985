#include "algorithms/embroidery/stitch_render.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

namespace atelier::embroidery {
namespace {

// One thread between two needle points, in frame pixels.
struct Segment {
  cv::Point2f a, b;
  cv::Vec3f bgr;       // thread colour, 0..255, with this stitch's variation applied
  int x0, y0, x1, y1;  // pixel box (inclusive) the thread may touch
};

// A reproducible spread per stitch (splitmix64 of seed and index), in [-1, 1].
double spread(std::uint64_t seed, std::uint64_t i) {
  std::uint64_t z = seed * 0x9E3779B97F4A7C15ull + i + 0x632BE59BD9B4E5ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) / static_cast<double>(1ull << 52) - 1.0;
}

std::vector<Segment> segments_of(const StitchPlan& plan, const StitchRenderParams& p, float radius) {
  const double cx = (p.size.width - 1) / 2.0, cy = (p.size.height - 1) / 2.0;
  auto to_px = [&](const StitchPoint& s) {
    return cv::Point2f(static_cast<float>(s.x_mm * p.px_per_mm + cx), static_cast<float>(s.y_mm * p.px_per_mm + cy));
  };
  std::vector<Segment> out;
  size_t block = 0;
  bool have_prev = false;
  cv::Point2f prev;
  const int margin = static_cast<int>(std::ceil(radius)) + 1;
  for (const StitchPoint& s : plan.points) {
    switch (s.kind) {
      case StitchKind::color_change: ++block; continue;
      case StitchKind::trim: continue;   // the thread is cut; the next jump moves the frame
      case StitchKind::end: break;
      case StitchKind::jump: prev = to_px(s), have_prev = true; continue;
      case StitchKind::stitch: {
        const cv::Point2f q = to_px(s);
        const cv::Point2f d = q - prev;
        if (have_prev && d.dot(d) > 1e-8f) {
          const std::uint32_t rgb = block < plan.colors_rgb.size() ? plan.colors_rgb[block] : 0x808080u;
          const float f = static_cast<float>(1.0 + p.variation * spread(p.seed, out.size()));
          Segment g{prev, q,
                    cv::Vec3f(static_cast<float>(rgb & 0xff), static_cast<float>((rgb >> 8) & 0xff),
                              static_cast<float>((rgb >> 16) & 0xff)) * f,
                    static_cast<int>(std::floor(std::min(prev.x, q.x))) - margin,
                    static_cast<int>(std::floor(std::min(prev.y, q.y))) - margin,
                    static_cast<int>(std::ceil(std::max(prev.x, q.x))) + margin,
                    static_cast<int>(std::ceil(std::max(prev.y, q.y))) + margin};
          // Entirely outside the frame: nothing to draw (and no huge loop over its box).
          if (g.x1 >= 0 && g.y1 >= 0 && g.x0 < p.size.width && g.y0 < p.size.height) out.push_back(g);
        }
        prev = q;
        have_prev = true;
        continue;
      }
    }
    break;   // end
  }
  return out;
}

// Light from the upper left (image y is down), a little above the fabric.
const cv::Vec3f kLight = cv::normalize(cv::Vec3f(-0.45f, -0.55f, 0.70f));
const cv::Vec3f kHalf = cv::normalize(kLight + cv::Vec3f(0, 0, 1));

}  // namespace

StitchRender render_stitches(const StitchPlan& plan, const StitchRenderParams& p) {
  if (p.size.width <= 0 || p.size.height <= 0) throw std::invalid_argument("stitch render: the frame is empty");
  if (!(p.px_per_mm > 0) || !std::isfinite(p.px_per_mm))
    throw std::invalid_argument("stitch render: px_per_mm must be positive");
  if (!(p.thread_width_mm > 0) || !std::isfinite(p.thread_width_mm))
    throw std::invalid_argument("stitch render: thread_width_mm must be positive");
  validate_plan(plan);

  const float r = static_cast<float>(0.5 * p.thread_width_mm * p.px_per_mm);   // thread radius, px
  const std::vector<Segment> segs = segments_of(plan, p, r);
  // Twist ridges about 0.3 mm apart; below ~3 px per ridge they would only alias, so they fade.
  const float twist_px = static_cast<float>(0.3 * p.px_per_mm);
  const float twist_amp = 0.14f * std::clamp((twist_px - 2.f) / 2.f, 0.f, 1.f);
  const float kTwoPi = 6.28318530718f;

  // Shading across a thread: a lit cylinder whose surface normal leans out with the signed
  // distance c from the axis (flanks dark, the highlight towards the light), box-filtered over
  // a pixel's width so a highlight narrower than a pixel does not sparkle on some pixels only.
  // It depends on the stitch only through its direction, so it is tabulated once over c in
  // [-r - 1, r + 1] (kLut entries) for kAngles directions across; pixels read the table.
  constexpr int kLut = 48, kSub = 8, kAngles = 64;
  const float lut_half = r + 1.f, lut_step = 2.f * lut_half / (kLut - 1);
  std::vector<float> shade_lut(kAngles * kLut), spec_lut(kAngles * kLut);
  for (int ai = 0; ai < kAngles; ++ai) {
    const float ang = kTwoPi * ai / kAngles;
    const cv::Point2f across(std::cos(ang), std::sin(ang));
    for (int i = 0; i < kLut; ++i) {
      const float c0 = -lut_half + i * lut_step;
      float sh = 0, sp = 0;
      for (int k = 0; k < kSub; ++k) {
        const float w = std::clamp(c0 + ((k + 0.5f) / kSub - 0.5f), -0.98f * r, 0.98f * r) / r;
        const cv::Vec3f n(w * across.x, w * across.y, std::sqrt(1.f - w * w));
        sh += 0.28f + 0.85f * std::max(0.f, n.dot(kLight));
        sp += std::pow(std::max(0.f, n.dot(kHalf)), 14.f);
      }
      shade_lut[ai * kLut + i] = sh / kSub;
      spec_lut[ai * kLut + i] = sp / kSub;
    }
  }

  // Premultiplied thread colour and coverage, composited in sewing order.
  cv::Mat3f color(p.size, cv::Vec3f(0, 0, 0));
  cv::Mat1f alpha(p.size, 0.f);
  // Row bands are independent (each walks every stitch in order), so the result does not
  // depend on how the bands are split.
  cv::parallel_for_(cv::Range(0, p.size.height), [&](const cv::Range& rows) {
    for (const Segment& g : segs) {
      const int y0 = std::max(g.y0, rows.start), y1 = std::min(g.y1, rows.end - 1);
      if (y0 > y1) continue;
      const int x0 = std::max(g.x0, 0), x1 = std::min(g.x1, p.size.width - 1);
      const cv::Point2f d = g.b - g.a;
      const float len2 = d.dot(d), len = std::sqrt(len2);
      const cv::Point2f along = d / len, across(-along.y, along.x);
      const int ai = static_cast<int>(std::lround(std::atan2(across.y, across.x) / kTwoPi * kAngles) + kAngles) % kAngles;
      const float* shade = &shade_lut[ai * kLut];
      const float* spec = &spec_lut[ai * kLut];
      for (int y = y0; y <= y1; ++y) {
        cv::Vec3f* crow = color.ptr<cv::Vec3f>(y);
        float* arow = alpha.ptr<float>(y);
        for (int x = x0; x <= x1; ++x) {
          const cv::Point2f v(x - g.a.x, y - g.a.y);
          const float a = v.dot(along);                 // along the thread from its start, px
          const float ta = std::clamp(a, 0.f, len);
          const cv::Point2f q = v - ta * along;         // from the axis (or its end) to the pixel
          // Coverage: the area of the pixel inside a thread at least a pixel wide.
          const float cov = std::clamp(r + 0.5f - std::sqrt(q.dot(q)), 0.f, 1.f);
          if (cov <= 0.f) continue;
          const float c = v.dot(across);
          const float fi = std::clamp((c + lut_half) / lut_step, 0.f, kLut - 1.001f);
          const int i = static_cast<int>(fi);
          const float f = fi - i;
          float sh = shade[i] + f * (shade[i + 1] - shade[i]);
          const float hi = spec[i] + f * (spec[i + 1] - spec[i]);
          // Past the needle point the thread dips into the fabric: its round end darkens.
          const float e = std::abs(a - ta) / r;
          if (e > 0) sh *= 1.f - 0.45f * std::min(1.f, e * e);
          if (twist_amp > 0) sh *= 1.f - twist_amp * (0.5f + 0.5f * std::cos(kTwoPi * (a + 1.2f * c) / twist_px));
          const cv::Vec3f lit = g.bgr * sh + cv::Vec3f(1, 1, 1) * (70.f * hi * (1.f - std::min(1.f, e)));
          crow[x] = lit * cov + crow[x] * (1.f - cov);
          arow[x] = cov + arow[x] * (1.f - cov);
        }
      }
    }
  });

  // The threads' soft shadow on the fabric, away from the light.
  const double sigma = std::max(0.6, 0.12 * p.px_per_mm);
  cv::Mat1f shadow;
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 0.15 * p.px_per_mm, 0, 1, 0.18 * p.px_per_mm);
  cv::warpAffine(alpha, shadow, shift, p.size, cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
  cv::GaussianBlur(shadow, shadow, cv::Size(), sigma);

  StitchRender out;
  out.image.create(p.size);
  out.coverage.create(p.size);
  out.stitches_drawn = static_cast<int>(segs.size());
  const cv::Vec3f fabric(p.fabric_bgr[0], p.fabric_bgr[1], p.fabric_bgr[2]);
  for (int y = 0; y < p.size.height; ++y) {
    const cv::Vec3f* c = color.ptr<cv::Vec3f>(y);
    const float* a = alpha.ptr<float>(y);
    const float* s = shadow.ptr<float>(y);
    cv::Vec3b* o = out.image.ptr<cv::Vec3b>(y);
    uchar* cv8 = out.coverage.ptr<uchar>(y);
    for (int x = 0; x < p.size.width; ++x) {
      const cv::Vec3f v = c[x] + fabric * ((1.f - 0.35f * std::min(1.f, s[x])) * (1.f - a[x]));
      o[x] = cv::Vec3b(cv::saturate_cast<uchar>(v[0]), cv::saturate_cast<uchar>(v[1]), cv::saturate_cast<uchar>(v[2]));
      cv8[x] = cv::saturate_cast<uchar>(255.f * a[x]);
    }
  }
  return out;
}

}  // namespace atelier::embroidery
