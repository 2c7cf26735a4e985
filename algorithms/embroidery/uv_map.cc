#include "algorithms/embroidery/uv_map.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

namespace atelier::embroidery {

cv::Mat1i nearest_point_index(cv::Size size, const std::vector<cv::Point2f>& points) {
  cv::Mat1i owner(size, -1);   // point index per seed pixel
  cv::Mat1b src(size, uchar(255));
  bool any = false;
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    const int x = static_cast<int>(std::lround(points[i].x)), y = static_cast<int>(std::lround(points[i].y));
    if (x < 0 || y < 0 || x >= size.width || y >= size.height || owner(y, x) >= 0) continue;
    owner(y, x) = i;
    src(y, x) = 0;
    any = true;
  }
  cv::Mat1i result(size, -1);
  if (!any) return result;
  cv::Mat1f dist;
  cv::Mat1i labels;
  cv::distanceTransform(src, dist, labels, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
  // Labels are numbered per seed pixel; read each seed's own label to map it to its point.
  int max_label = 0;
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) max_label = std::max(max_label, labels(y, x));
  std::vector<int> of_label(max_label + 1, -1);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      if (owner(y, x) >= 0) of_label[labels(y, x)] = owner(y, x);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) result(y, x) = of_label[labels(y, x)];
  return result;
}

}  // namespace atelier::embroidery
