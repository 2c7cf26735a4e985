#include "algorithms/embroidery/directions.h"

#include <cmath>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

namespace atelier::embroidery {
namespace {

constexpr double kPi = 3.14159265358979323846;

double fold(double a) {
  a = std::fmod(a, kPi);
  return a < 0 ? a + kPi : a;
}

// The mask padded by one pixel so that its border pixels have gradients.
cv::Mat1b padded(const cv::Mat1b& mask) {
  cv::Mat1b p;
  cv::copyMakeBorder(mask, p, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
  return p;
}

// Doubled-angle mean of the mask's gradient directions: the direction across a stroke.
double across_direction(const cv::Mat1b& mask, bool* ok) {
  const cv::Mat1b p = padded(mask);
  cv::Mat1f gx, gy;
  cv::Sobel(p, gx, CV_32F, 1, 0, 3);
  cv::Sobel(p, gy, CV_32F, 0, 1, 3);
  double c = 0, s = 0;
  for (int y = 0; y < p.rows; ++y)
    for (int x = 0; x < p.cols; ++x) {
      const double a = gx(y, x), b = gy(y, x);
      // (a + ib)^2 / |.| weighs each gradient by its magnitude, on the doubled angle.
      const double m2 = a * a + b * b;   // most pixels are flat: no square root for them
      if (m2 <= 0) continue;
      const double m = std::sqrt(m2);
      c += (a * a - b * b) / m;
      s += 2 * a * b / m;
    }
  *ok = std::hypot(c, s) > 1e-6;
  return fold(0.5 * std::atan2(s, c));
}

// The long axis of the minimum-area bounding box. The hull of the outer contours is the hull of
// the region, so only contour points go to minAreaRect (a large region has millions of pixels).
double bbox_direction(const std::vector<std::vector<cv::Point>>& contours) {
  std::vector<cv::Point> pts;
  for (const auto& c : contours) pts.insert(pts.end(), c.begin(), c.end());
  if (pts.size() < 3) return 0.0;
  const cv::RotatedRect r = cv::minAreaRect(pts);
  cv::Point2f c[4];
  r.points(c);
  // The longer of the two sides from c[1].
  const cv::Point2f a = c[0] - c[1], b = c[2] - c[1];
  const cv::Point2f l = a.dot(a) >= b.dot(b) ? a : b;
  return fold(std::atan2(l.y, l.x));
}

std::vector<std::vector<cv::Point>> outer_contours(const cv::Mat1b& mask) {
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(padded(mask), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  return contours;
}

}  // namespace

double axis_mean(const std::vector<double>& angles, const std::vector<double>& weights) {
  double c = 0, s = 0;
  for (size_t i = 0; i < angles.size(); ++i) {
    c += weights[i] * std::cos(2 * angles[i]);
    s += weights[i] * std::sin(2 * angles[i]);
  }
  return fold(0.5 * std::atan2(s, c));
}

std::vector<double> region_directions(const Segmentation& seg) {
  const int n = static_cast<int>(seg.regions.size());
  std::vector<double> dir(n, 0.0);
  // Pass 1: satin and edge regions from their own shape.
  cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const Region& r = seg.regions[i];
      if (r.style == Style::long_short || r.mask.empty()) continue;
      bool ok = false;
      const double across = across_direction(r.mask, &ok);
      if (!ok) {
        dir[i] = bbox_direction(outer_contours(r.mask));
        continue;
      }
      dir[i] = r.style == Style::satin ? across : fold(across + kPi / 2);
    }
  });
  // Pass 2: long-short regions from the satin/edge neighbours along their external contour.
  cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& range) {
    std::vector<double> angles, weights;
    for (int i = range.start; i < range.end; ++i) {
      const Region& r = seg.regions[i];
      if (r.style != Style::long_short || r.mask.empty()) continue;
      const auto contours = outer_contours(r.mask);
      angles.clear();
      weights.clear();
      for (const auto& contour : contours)
        for (const cv::Point& q : contour) {
          // q is in padded coordinates: image pixel = bbox.tl() + q - (1,1).
          const cv::Point p = r.bbox.tl() + q - cv::Point(1, 1);
          static const cv::Point kN4[4] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
          for (const cv::Point& d : kN4) {
            const cv::Point o = p + d;
            if (o.x < 0 || o.y < 0 || o.x >= seg.region_id.cols || o.y >= seg.region_id.rows) continue;
            const int other = seg.region_id(o);
            if (other < 0 || other == i || seg.regions[other].style == Style::long_short) continue;
            angles.push_back(dir[other]);
            weights.push_back(1.0);
          }
        }
      dir[i] = angles.empty() ? bbox_direction(contours) : axis_mean(angles, weights);
    }
  });
  return dir;
}

}  // namespace atelier::embroidery
