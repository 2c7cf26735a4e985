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
  cv::Mat3f out(tile_lab.size());
  // Chang et al.'s L transfer with one palette entry: monotone, keeps black and white fixed.
  double sum = 0;
  int n = 0;
  for (int y = 0; y < tile_lab.rows; ++y)
    for (int x = 0; x < tile_lab.cols; ++x) {
      const cv::Vec3f p = tile_lab(y, x);
      const float l = p[0] <= ml ? p[0] * tl / ml : tl + (p[0] - ml) * (100.f - tl) / (100.f - ml);
      out(y, x) = cv::Vec3f(l, p[1] + da, p[2] + db);
      if (alpha(y, x) >= 128) {
        sum += l;
        ++n;
      }
    }
  // The piecewise map moves the mean a little; shift it back onto the target.
  const float shift = n > 0 ? tl - static_cast<float>(sum / n) : 0.f;
  for (auto& p : out) p[0] = std::clamp(p[0] + shift, 0.f, 100.f);
  cv::Mat3f bgr;
  cv::cvtColor(out, bgr, cv::COLOR_Lab2BGR);
  cv::Mat3b result;
  bgr.convertTo(result, CV_8U, 255.0);
  return result;
}

}  // namespace atelier::embroidery
