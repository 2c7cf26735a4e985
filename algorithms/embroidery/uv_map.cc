#include "algorithms/embroidery/uv_map.h"

#include <algorithm>
#include <cmath>
#include <vector>

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
  // Labels are numbered per seed pixel (1..seeds); read each seed's own label to map it to its
  // point. Only the seeds are visited for that, not the whole box.
  std::vector<cv::Point> seeds;
  seeds.reserve(points.size());
  for (const cv::Point2f& q : points) {
    const int x = static_cast<int>(std::lround(q.x)), y = static_cast<int>(std::lround(q.y));
    if (x >= 0 && y >= 0 && x < size.width && y < size.height) seeds.emplace_back(x, y);
  }
  int max_label = 0;
  for (const cv::Point& q : seeds) max_label = std::max(max_label, labels(q));
  std::vector<int> of_label(max_label + 1, -1);
  for (const cv::Point& q : seeds) of_label[labels(q)] = owner(q);
  for (int y = 0; y < size.height; ++y) {
    const int* l = labels.ptr<int>(y);
    int* r = result.ptr<int>(y);
    for (int x = 0; x < size.width; ++x) r[x] = l[x] >= 0 && l[x] <= max_label ? of_label[l[x]] : -1;
  }
  return result;
}

RegionUV region_uv_with_angles(const cv::Rect& box, const cv::Mat1b& mask, double direction) {
  RegionUV out;
  out.box = box;
  out.mask = mask.clone();
  out.uv = cv::Mat2f(mask.size(), cv::Vec2f(0, 0));
  out.angle = cv::Mat1f(mask.size(), static_cast<float>(direction));
  out.direction = static_cast<float>(direction);
  return out;
}

}  // namespace atelier::embroidery
