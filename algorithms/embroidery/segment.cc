#include "algorithms/embroidery/segment.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <numeric>
#include <stdexcept>

namespace atelier::embroidery {
namespace {

struct ComponentResult {
  std::vector<Region> regions;  // id unset
  bool forced = false;
};

// The component's regions: 4-connected pieces of each style within its bounding box.
void cut_regions(const cv::Mat1b& style, const cv::Mat1b& mask, int area_px, const cv::Rect& box,
                 int component, int color, ComponentResult& out) {
  // Each style's bounding box within the component's (labelling only there).
  int x0[kStyleCount], y0[kStyleCount], x1[kStyleCount], y1[kStyleCount];
  for (int k = 0; k < kStyleCount; ++k) x0[k] = style.cols, y0[k] = style.rows, x1[k] = y1[k] = -1;
  for (int y = 0; y < style.rows; ++y) {
    const uchar *s = style[y], *m = mask[y];
    for (int x = 0; x < style.cols; ++x)
      if (m[x] && s[x] < kStyleCount) {
        const int k = s[x];
        x0[k] = std::min(x0[k], x), x1[k] = std::max(x1[k], x);
        y0[k] = std::min(y0[k], y), y1[k] = std::max(y1[k], y);
      }
  }
  int present = 0, first = -1;
  for (int k = 0; k < kStyleCount; ++k)
    if (x1[k] >= 0) ++present, first = first < 0 ? k : first;
  if (present == 1) {
    // One style: the one region is the (4-connected) component itself.
    Region r;
    r.color = color;
    r.component = component;
    r.style = Style(first);
    r.bbox = box;  // the component's bounding box is tight
    r.mask = mask.clone();
    r.area_px = area_px;
    out.regions.push_back(std::move(r));
    return;
  }
  for (int s = 0; s < kStyleCount; ++s) {
    if (x1[s] < 0) continue;
    const cv::Rect sub(x0[s], y0[s], x1[s] - x0[s] + 1, y1[s] - y0[s] + 1);
    cv::Mat1b sm = style(sub) == s;
    cv::Mat1i lab;
    cv::Mat stats, centroids;
    const int n = cv::connectedComponentsWithStats(sm, lab, stats, centroids, 4, CV_32S);
    for (int i = 1; i < n; ++i) {
      Region r;
      r.color = color;
      r.component = component;
      r.style = Style(s);
      const cv::Rect local(stats.at<int>(i, cv::CC_STAT_LEFT), stats.at<int>(i, cv::CC_STAT_TOP),
                           stats.at<int>(i, cv::CC_STAT_WIDTH), stats.at<int>(i, cv::CC_STAT_HEIGHT));
      r.bbox = local + sub.tl() + box.tl();
      r.mask = lab(local) == i;
      r.area_px = stats.at<int>(i, cv::CC_STAT_AREA);
      out.regions.push_back(std::move(r));
    }
  }
}

}  // namespace

Segmentation segment(const cv::Mat& image, const ColorParams& cp, const LabelParams& lp) {
  if (image.empty()) throw std::invalid_argument("segment: empty image");
  validate_color_params(cp);
  validate_label_params(lp);
  Segmentation seg;
  seg.size = image.size();
  ColorExtraction ce = extract_colors(image, cp);
  Components comp = color_components(ce.color_index, static_cast<int>(ce.palette.bgr.size()), cp.min_area_px);
  const std::vector<int> remap = drop_unused_colors(ce.palette, ce.color_index);
  for (int& c : comp.color) c = remap[c];
  // Specks took their neighbour's colour: each thread is again the mean of what it sews.
  set_palette_to_means(ce.palette, ce.color_index, ce.lab);
  seg.palette = std::move(ce.palette);
  seg.color_index = ce.color_index;
  seg.component = comp.id;
  const int n = static_cast<int>(comp.color.size());
  seg.components = n;

  // Largest components first, one per stripe, so the two threads stay busy to the end.
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return comp.area_px[a] > comp.area_px[b]; });
  std::vector<ComponentResult> results(n);
  cv::parallel_for_(
      cv::Range(0, n),
      [&](const cv::Range& r) {
        for (int i = r.start; i < r.end; ++i) {
          const int c = order[i];
          const cv::Rect box = comp.bbox[c];
          const cv::Mat1b mask = comp.id(box) == c;
          bool forced = false;
          const cv::Mat1b style = label_component(mask, box.tl(), image.size(), lp, cp.min_area_px, &forced);
          results[c].forced = forced;
          cut_regions(style, mask, comp.area_px[c], box, c, comp.color[c], results[c]);
        }
      },
      n);

  for (int c = 0; c < n; ++c) {
    seg.components_forced_long_short += results[c].forced;
    for (Region& r : results[c].regions) {
      r.id = static_cast<int>(seg.regions.size());
      seg.regions.push_back(std::move(r));
    }
  }
  seg.region_id.create(seg.size);
  seg.region_id.setTo(-1);
  cv::parallel_for_(cv::Range(0, static_cast<int>(seg.regions.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) seg.region_id(seg.regions[i].bbox).setTo(i, seg.regions[i].mask);
  });
  return seg;
}

}  // namespace atelier::embroidery
