#include "algorithms/parquetry/features.h"

#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace atelier::parquetry {

cv::Mat to_gray(const cv::Mat& image) {
  if (image.type() == CV_8UC1) return image;
  cv::Mat gray;
  if (image.type() == CV_8UC3) {
    cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  } else if (image.type() == CV_8UC4) {
    cv::cvtColor(image, gray, cv::COLOR_BGRA2GRAY);
  } else {
    throw std::invalid_argument("parquetry: images must be 8-bit grey, BGR or BGRA");
  }
  return gray;
}

cv::Mat intensity(const cv::Mat& gray) {
  cv::Mat out;
  gray.convertTo(out, CV_32F, 1.0 / 255.0);
  return out;
}

cv::Mat edge(const cv::Mat& intens) {
  cv::Mat gx, gy, mag;
  cv::Sobel(intens, gx, CV_32F, 1, 0, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
  cv::Sobel(intens, gy, CV_32F, 0, 1, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
  cv::magnitude(gx, gy, mag);
  return mag * 0.25;
}

void add_histogram(std::array<double, 256>& hist, const cv::Mat& gray, const cv::Mat& mask) {
  for (int y = 0; y < gray.rows; ++y) {
    const uchar* g = gray.ptr<uchar>(y);
    const uchar* m = mask.empty() ? nullptr : mask.ptr<uchar>(y);
    for (int x = 0; x < gray.cols; ++x) {
      if (!m || m[x]) hist[g[x]] += 1;
    }
  }
}

std::array<float, 256> matching_lut(const std::array<double, 256>& target_hist,
                                    const std::array<double, 256>& wood_hist, double w_hist) {
  auto cdf = [](const std::array<double, 256>& h) {
    std::array<double, 256> c{};
    double sum = 0;
    for (int i = 0; i < 256; ++i) c[i] = (sum += h[i]);
    if (sum > 0) {
      for (double& v : c) v /= sum;
    }
    return std::pair{c, sum};
  };
  auto [ct, nt] = cdf(target_hist);
  auto [cw, nw] = cdf(wood_hist);
  std::array<float, 256> lut{};
  int u = 0;
  for (int v = 0; v < 256; ++v) {
    double equalized = v;
    if (nt > 0 && nw > 0) {
      // Both CDFs are monotone, so the wood level only moves forward.
      while (u < 255 && cw[u] < ct[v] - 1e-12) ++u;
      equalized = u;
    }
    lut[v] = static_cast<float>(((1.0 - w_hist) * v + w_hist * equalized) / 255.0);
  }
  return lut;
}

cv::Mat apply_lut(const cv::Mat& gray, const std::array<float, 256>& lut) {
  cv::Mat out(gray.size(), CV_32F);
  for (int y = 0; y < gray.rows; ++y) {
    const uchar* g = gray.ptr<uchar>(y);
    float* o = out.ptr<float>(y);
    for (int x = 0; x < gray.cols; ++x) o[x] = lut[g[x]];
  }
  return out;
}

}  // namespace atelier::parquetry
