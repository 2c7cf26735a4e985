#include "algorithms/knit/similarity.h"

#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace atelier::knit {

double blurred_ssim(const cv::Mat& source_gray, const cv::Mat& grid, double sigma_stitches) {
  if (source_gray.empty() || source_gray.type() != CV_8UC1)
    throw std::invalid_argument("blurred_ssim: the source must be a non-empty CV_8UC1 image");
  if (grid.type() != CV_8UC1 || grid.size() != source_gray.size())
    throw std::invalid_argument("blurred_ssim: the grid must be CV_8UC1 of the source's size");
  if (!(sigma_stitches >= 0))
    throw std::invalid_argument("blurred_ssim: sigma_stitches must be >= 0");
  cv::Mat a, b;
  source_gray.convertTo(a, CV_32F);
  // Pattern as seen in print: contrast stitches (1) black, background (0) white.
  cv::Mat dark = grid != 0;  // 255 where contrast
  dark.convertTo(b, CV_32F, -1.0, 255.0);
  // Seen from a distance, stitches blur together.
  if (sigma_stitches > 0) {
    cv::GaussianBlur(a, a, cv::Size(), sigma_stitches, sigma_stitches, cv::BORDER_REFLECT);
    cv::GaussianBlur(b, b, cv::Size(), sigma_stitches, sigma_stitches, cv::BORDER_REFLECT);
  }
  // Wang et al. 2004: local statistics under an 11x11 Gaussian window of sigma 1.5.
  const double c1 = (0.01 * 255) * (0.01 * 255), c2 = (0.03 * 255) * (0.03 * 255);
  const cv::Size win(11, 11);
  auto local_mean = [&](const cv::Mat& m) {
    cv::Mat out;
    cv::GaussianBlur(m, out, win, 1.5, 1.5, cv::BORDER_REFLECT);
    return out;
  };
  const cv::Mat mu_a = local_mean(a), mu_b = local_mean(b);
  const cv::Mat mu_a2 = mu_a.mul(mu_a), mu_b2 = mu_b.mul(mu_b), mu_ab = mu_a.mul(mu_b);
  const cv::Mat var_a = local_mean(a.mul(a)) - mu_a2;
  const cv::Mat var_b = local_mean(b.mul(b)) - mu_b2;
  const cv::Mat cov = local_mean(a.mul(b)) - mu_ab;
  cv::Mat num = (2 * mu_ab + c1).mul(2 * cov + c2);
  cv::Mat den = (mu_a2 + mu_b2 + c1).mul(var_a + var_b + c2);
  cv::Mat ssim_map;
  cv::divide(num, den, ssim_map);
  return cv::mean(ssim_map)[0];
}

}  // namespace atelier::knit
