#include "algorithms/embroidery/recolor.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>

namespace atelier::embroidery {

cv::Mat3f to_lab(const cv::Mat3b& bgr) {
  cv::Mat3f f, lab;
  bgr.convertTo(f, CV_32F, 1.0 / 255.0);
  cv::cvtColor(f, lab, cv::COLOR_BGR2Lab);
  return lab;
}

cv::Vec3f tile_mean_lab(const cv::Mat3b& color, const cv::Mat1b& alpha) {
  const cv::Mat3f lab = to_lab(color);
  cv::Mat1b thread = alpha >= 128;
  if (cv::countNonZero(thread) == 0) thread.setTo(255);
  const cv::Scalar m = cv::mean(lab, thread);
  return {static_cast<float>(m[0]), static_cast<float>(m[1]), static_cast<float>(m[2])};
}

cv::Mat3b recolor_tile(const cv::Mat3f& tile_lab, const cv::Mat1b& alpha, const cv::Vec3f& mean_lab,
                       const cv::Vec3f& target_lab, double max_L) {
  const float tl = static_cast<float>(std::clamp<double>(std::min<double>(target_lab[0], max_L), 0.0, 100.0));
  const float ml = std::clamp(mean_lab[0], 0.5f, 99.5f);
  const float da = target_lab[1] - mean_lab[1], db = target_lab[2] - mean_lab[2];
  // Thread pixels' L range around their mean.
  float lo = ml, hi = ml;
  for (int y = 0; y < tile_lab.rows; ++y)
    for (int x = 0; x < tile_lab.cols; ++x)
      if (alpha(y, x) >= 128) lo = std::min(lo, tile_lab(y, x)[0]), hi = std::max(hi, tile_lab(y, x)[0]);
  // A monotone linear L transfer: the shading's deviations from the mean are kept, scaled down
  // only as far as needed to stay inside [0, 100], but never below a quarter so that black and
  // white thread still show their twist and sheen.
  float k = 1.f;
  if (ml - lo > 1e-3f) k = std::min(k, tl / (ml - lo));
  if (hi - ml > 1e-3f) k = std::min(k, (100.f - tl) / (hi - ml));
  k = std::max(k, 0.25f);
  // A target lighter than max_L is capped (the overexposure fix): its sheen must not carry it
  // back above the cap, so above the mean the deviations reach at most 3 over max_L (a narrow
  // satin column shows mostly its crest).
  float k_hi = k;
  if (target_lab[0] > max_L && hi - ml > 1e-3f) k_hi = std::min(k, 3.f / (hi - ml));
  cv::Mat3f out(tile_lab.size());
  double sum = 0;
  int n = 0;
  for (int y = 0; y < tile_lab.rows; ++y)
    for (int x = 0; x < tile_lab.cols; ++x) {
      const cv::Vec3f p = tile_lab(y, x);
      const float l = std::clamp(tl + (p[0] - ml) * (p[0] > ml ? k_hi : k), 0.f, 100.f);
      out(y, x) = cv::Vec3f(l, p[1] + da, p[2] + db);
      if (alpha(y, x) >= 128) {
        sum += l;
        ++n;
      }
    }
  // Clamping at black or white moves the mean a little; shift it back onto the target.
  const float shift = n > 0 ? tl - static_cast<float>(sum / n) : 0.f;
  for (auto& p : out) p[0] = std::clamp(p[0] + shift, 0.f, 100.f);
  cv::Mat3f bgr;
  cv::cvtColor(out, bgr, cv::COLOR_Lab2BGR);
  cv::Mat3b result;
  bgr.convertTo(result, CV_8U, 255.0);
  return result;
}

}  // namespace atelier::embroidery
