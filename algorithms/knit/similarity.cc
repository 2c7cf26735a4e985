#include "algorithms/knit/similarity.h"

#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace atelier::knit {
namespace {

// Wang et al. 2004: local statistics under an 11x11 Gaussian window of sigma 1.5.
constexpr double kC1 = (0.01 * 255) * (0.01 * 255), kC2 = (0.03 * 255) * (0.03 * 255);

cv::Mat local_mean(const cv::Mat& m) {
  cv::Mat out;
  cv::GaussianBlur(m, out, cv::Size(11, 11), 1.5, 1.5, cv::BORDER_REFLECT);
  return out;
}

// Seen from a distance, stitches blur together.
void distance_blur(cv::Mat& m, double sigma) {
  if (sigma > 0) cv::GaussianBlur(m, m, cv::Size(), sigma, sigma, cv::BORDER_REFLECT);
}

}  // namespace

BlurredSsim::BlurredSsim(const cv::Mat& source_gray, double sigma_stitches) : sigma_(sigma_stitches) {
  if (source_gray.empty() || source_gray.type() != CV_8UC1)
    throw std::invalid_argument("blurred_ssim: the source must be a non-empty CV_8UC1 image");
  if (!(sigma_stitches >= 0))
    throw std::invalid_argument("blurred_ssim: sigma_stitches must be >= 0");
  source_gray.convertTo(a_, CV_32F);
  distance_blur(a_, sigma_);
  mu_a_ = local_mean(a_);
  mu_a2_ = mu_a_.mul(mu_a_);
  var_a_ = local_mean(a_.mul(a_)) - mu_a2_;
}

double BlurredSsim::operator()(const cv::Mat& grid) const {
  if (grid.type() != CV_8UC1 || grid.size() != a_.size())
    throw std::invalid_argument("blurred_ssim: the grid must be CV_8UC1 of the source's size");
  cv::Mat b;
  // Pattern as seen in print: contrast stitches (1) black, background (0) white.
  cv::Mat dark = grid != 0;  // 255 where contrast
  dark.convertTo(b, CV_32F, -1.0, 255.0);
  distance_blur(b, sigma_);
  const cv::Mat mu_b = local_mean(b);
  const cv::Mat mu_b2 = mu_b.mul(mu_b), mu_ab = mu_a_.mul(mu_b);
  const cv::Mat var_b = local_mean(b.mul(b)) - mu_b2;
  const cv::Mat cov = local_mean(a_.mul(b)) - mu_ab;
  cv::Mat num = (2 * mu_ab + kC1).mul(2 * cov + kC2);
  cv::Mat den = (mu_a2_ + mu_b2 + kC1).mul(var_a_ + var_b + kC2);
  cv::Mat ssim_map;
  cv::divide(num, den, ssim_map);
  return cv::mean(ssim_map)[0];
}

double blurred_ssim(const cv::Mat& source_gray, const cv::Mat& grid, double sigma_stitches) {
  if (source_gray.empty() || source_gray.type() != CV_8UC1)
    throw std::invalid_argument("blurred_ssim: the source must be a non-empty CV_8UC1 image");
  if (grid.type() != CV_8UC1 || grid.size() != source_gray.size())
    throw std::invalid_argument("blurred_ssim: the grid must be CV_8UC1 of the source's size");
  return BlurredSsim(source_gray, sigma_stitches)(grid);
}

}  // namespace atelier::knit
