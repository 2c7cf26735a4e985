// The embroidery design's shared vocabulary: stitch styles, regions and the segmentation that
// the paper's section 4 produces (segment.h) and that synthesis (section 5) and stitch
// generation consume.
// Units: image pixels (x right, y down); px_per_mm converts to the design's physical size.
// Value types; no I/O; thread-compatible (const access from several threads is safe).
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace atelier::embroidery {

// The paper's three stitch styles. The values index per-style arrays.
enum class Style : int { long_short = 0, satin = 1, edge = 2 };
constexpr int kStyleCount = 3;

inline const char* style_name(Style s) {
  switch (s) {
    case Style::long_short: return "long_short";
    case Style::satin: return "satin";
    case Style::edge: return "edge";
  }
  return "?";
}

// One embroidery region: 4-connected pixels of one palette colour carrying one stitch style.
struct Region {
  int id = 0;          // its index in Segmentation::regions
  int color = 0;       // palette index
  int component = 0;   // the 4-connected single-colour component it was cut from
  Style style = Style::long_short;
  cv::Rect bbox;       // image pixels
  cv::Mat1b mask;      // bbox.size(); 255 = pixel belongs to the region
  int area_px = 0;
};

// The colours the image was reduced to (paper 4: median filter + clustering in CIELab).
struct Palette {
  std::vector<cv::Vec3b> bgr;   // 8-bit sRGB, OpenCV's B,G,R order
  std::vector<cv::Vec3f> lab;   // CIELab, L in [0, 100], a and b about [-128, 127]
};

struct Segmentation {
  cv::Size size;            // the input image's size in pixels
  Palette palette;
  cv::Mat1i color_index;    // per pixel: palette index, or -1 = not sewn (transparent or
                            // the fabric showing through, see ColorParams::background)
  cv::Mat1i component;      // per pixel: component id, or -1 = not sewn
  cv::Mat1i region_id;      // per pixel: index into regions, or -1 = not sewn
  std::vector<Region> regions;
  int components = 0;               // number of single-colour components
  int components_forced_long_short = 0;  // SWT failures over n^0.8 (paper 4)
};

}  // namespace atelier::embroidery
