// Helpers shared by the synthesis, UV map, direction and texture tests: segmentations built
// from drawn label images, so that every region's shape, colour and style is known.
#pragma once

#include <opencv2/imgproc.hpp>

#include <vector>

#include "algorithms/embroidery/segment.h"

namespace atelier::embroidery::test {

inline constexpr double kPi = 3.14159265358979323846;

inline cv::Vec3f lab_of(const cv::Vec3b& bgr) {
  cv::Mat3f f(1, 1, cv::Vec3f(bgr[0] / 255.f, bgr[1] / 255.f, bgr[2] / 255.f)), lab;
  cv::cvtColor(f, lab, cv::COLOR_BGR2Lab);
  return lab(0, 0);
}

// A segmentation from a label image (-1 = not sewn, i = region i), one palette colour and one
// style per region.
inline Segmentation make_seg(const cv::Mat1i& labels, const std::vector<cv::Vec3b>& bgr,
                             const std::vector<Style>& styles) {
  Segmentation seg;
  seg.size = labels.size();
  seg.region_id = labels.clone();
  seg.color_index = labels.clone();
  seg.component = labels.clone();
  for (const cv::Vec3b& c : bgr) {
    seg.palette.bgr.push_back(c);
    seg.palette.lab.push_back(lab_of(c));
  }
  for (int i = 0; i < static_cast<int>(bgr.size()); ++i) {
    Region r;
    r.id = i;
    r.color = i;
    r.component = i;
    r.style = styles[i];
    const cv::Mat1b m = labels == i;
    r.bbox = cv::boundingRect(m);
    r.mask = m(r.bbox).clone();
    r.area_px = cv::countNonZero(r.mask);
    seg.regions.push_back(r);
  }
  seg.components = static_cast<int>(bgr.size());
  return seg;
}

// A background of long-short, a disc of long-short, a satin stripe and an edge line.
inline Segmentation drawn_design() {
  cv::Mat1i labels(300, 400, -1);
  cv::rectangle(labels, cv::Rect(10, 10, 380, 280), 0, cv::FILLED);
  cv::circle(labels, cv::Point(120, 150), 70, 1, cv::FILLED);
  cv::line(labels, cv::Point(230, 40), cv::Point(360, 250), 2, 16);
  cv::line(labels, cv::Point(40, 270), cv::Point(370, 270), 3, 3);
  return make_seg(labels, {{40, 90, 30}, {200, 60, 40}, {30, 200, 230}, {20, 20, 160}},
                  {Style::long_short, Style::long_short, Style::satin, Style::edge});
}

}  // namespace atelier::embroidery::test
