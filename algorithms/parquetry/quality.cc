#include "algorithms/parquetry/quality.h"

#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace atelier::parquetry {

namespace {

cv::Mat grey_float(const cv::Mat& image) {
  cv::Mat grey, out;
  switch (image.type()) {
    case CV_8UC1: grey = image; break;
    case CV_8UC3: cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY); break;
    case CV_8UC4: cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY); break;
    default: throw std::invalid_argument("blurred_ssim: images must be 8-bit grey, BGR or BGRA");
  }
  grey.convertTo(out, CV_32F);
  return out;
}

cv::Mat window(const cv::Mat& m) {
  cv::Mat out;
  cv::GaussianBlur(m, out, cv::Size(11, 11), 1.5, 1.5, cv::BORDER_REFLECT);
  return out;
}

}  // namespace

double blurred_ssim(const cv::Mat& result, const cv::Mat& target, double px_per_mm) {
  return cv::mean(blurred_ssim_map(result, target, px_per_mm))[0];
}

int blurred_ssim_reach_px(double px_per_mm) {
  // GaussianBlur's kernel for float images with ksize 0: cvRound(sigma * 8 + 1) | 1 wide.
  const int blur = (cvRound(kQualityBlurMm * px_per_mm * 8 + 1) | 1) / 2;
  return blur + 5;  // + the 11 x 11 window's radius
}

cv::Mat blurred_ssim_map(const cv::Mat& result, const cv::Mat& target, double px_per_mm) {
  if (result.empty() || target.empty()) throw std::invalid_argument("blurred_ssim: empty image");
  if (result.size() != target.size()) {
    throw std::invalid_argument("blurred_ssim: the images differ in size");
  }
  if (!(px_per_mm > 0)) throw std::invalid_argument("blurred_ssim: px_per_mm must be > 0");
  const double sigma = kQualityBlurMm * px_per_mm;
  cv::Mat a = grey_float(result), b = grey_float(target);
  cv::GaussianBlur(a, a, cv::Size(), sigma, sigma, cv::BORDER_REFLECT);
  cv::GaussianBlur(b, b, cv::Size(), sigma, sigma, cv::BORDER_REFLECT);

  constexpr double C1 = (0.01 * 255) * (0.01 * 255), C2 = (0.03 * 255) * (0.03 * 255);
  const cv::Mat mu_a = window(a), mu_b = window(b);
  const cv::Mat mu_aa = mu_a.mul(mu_a), mu_bb = mu_b.mul(mu_b), mu_ab = mu_a.mul(mu_b);
  const cv::Mat s_aa = window(a.mul(a)) - mu_aa;
  const cv::Mat s_bb = window(b.mul(b)) - mu_bb;
  const cv::Mat s_ab = window(a.mul(b)) - mu_ab;
  cv::Mat num = (2 * mu_ab + C1).mul(2 * s_ab + C2);
  cv::Mat den = (mu_aa + mu_bb + C1).mul(s_aa + s_bb + C2);
  cv::Mat ssim;
  cv::divide(num, den, ssim);
  return ssim;
}

}  // namespace atelier::parquetry
