// Paper section 4, first step: colour extraction. A median filter removes noise and detail,
// the pixels are clustered in CIELab, every pixel takes its nearest cluster centre, and the
// image falls apart into 4-connected single-colour components (tiny ones merged away).
// Units: image pixels; colour differences are CIE76 dE in CIELab.
// Pure functions; no shared state; safe to call from several threads. Internally parallel
// (cv::parallel_for_). Deterministic: the same image and parameters give the same result.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "algorithms/embroidery/design.h"

namespace atelier::embroidery {

// Which pixels are sewn. Transparent pixels (alpha < 128) are never sewn.
//  automatic: in an image with no transparent pixel (no alpha channel, or alpha >= 128
//             everywhere: an opaque RGBA PNG is the same picture as its RGB), a near-white
//             cluster (L > 90, chroma < 12) that takes more than half of the image's border
//             pixels is the fabric showing through: not sewn. In a partly transparent image
//             the transparency is the background and an opaque white is a white thread.
//  sew:       every opaque pixel is sewn.
enum class Background { automatic, sew };

// Colour distances are CIE76 (Euclidean in CIELab, L 0..100): k-means minimises exactly this,
// and at the sizes that decide threads here (dE 8 spread, 15 distinct) CIE76 and CIEDE2000
// agree on what is one colour; CIE76 overstates saturated differences, which only errs
// towards keeping a colour.
struct ColorParams {
  int median_ksize = 3;      // odd, >= 1 (1 = no filter); 5 and up erase 2-px lines
  int colors = 0;            // 0 = automatic; otherwise this many clusters (<= max_colors),
                             // counting a background cluster; colours left without a pixel
                             // are dropped from the palette
  int max_colors = 12;       // cap for automatic and for `colors`; 1..64
  double auto_delta_e = 8;   // automatic: the smallest k whose every cluster (of at least 1 %
                             // of the samples) has half its samples within this dE of its
                             // centre, with at most 0.5 % of all samples farther than 50 from
                             // theirs (thin lines); a patch is one colour when its pixels lie
                             // within this mean dE of their mean; > 0
  double distinct_delta_e = 15;  // automatic: a patch of at least 2 x min_area_px (thicker than
                                 // a boundary line) farther than this from every thread gets a
                                 // thread of its own, replacing the two closest threads by one
                                 // at max_colors when those are closer than it; > 0
  int min_area_px = 16;      // components smaller than this are merged into the neighbour they
                             // share the longest border with; >= 1. A small component with no
                             // sewn neighbour is not sewn (no one-stitch regions)
  Background background = Background::automatic;
};

// Throws std::invalid_argument naming the bad parameter.
void validate_color_params(const ColorParams& p);

struct ColorExtraction {
  Palette palette;          // only colours that some sewn pixel uses; each the CIELab mean
                            // of the filtered pixels it sews (palette.bgr: the same, 8-bit)
  cv::Mat1i color_index;    // image size; palette index, or -1 = not sewn
  cv::Mat3f lab;            // image size; the median-filtered image in CIELab (L 0..100)
};

// image: CV_8UC3 BGR or CV_8UC4 BGRA, not empty (else std::invalid_argument).
// Automatic colours: k-means on a fixed-seed subsample of at most 8000 opaque pixels for the
// smallest k that holds them (auto_delta_e), then over all pixels the patches no thread is
// within distinct_delta_e of get their own (at most 2 x max_colors rounds, each refined by at
// most 3 Lloyd steps over the image), then threads within dE 5 of each other are one. Every
// pixel takes its nearest centre. Does not merge small components (see below).
ColorExtraction extract_colors(const cv::Mat& image, const ColorParams& p);

// Sets every palette colour to the CIELab mean of `lab` over the pixels color_index gives it
// (a colour without pixels keeps its value), and palette.bgr to match.
void set_palette_to_means(Palette& palette, const cv::Mat1i& color_index, const cv::Mat3f& lab);

struct Components {
  cv::Mat1i id;                // image size; component id, or -1 = not sewn
  std::vector<int> color;      // per component: palette index
  std::vector<int> area_px;    // per component
  std::vector<cv::Rect> bbox;  // per component, image pixels
};

// 4-connected single-colour components of color_index (-1 = not sewn, ignored). Components
// under min_area_px are merged, smallest first, into the neighbour with the longest shared
// 4-connected border and take its colour; one with no sewn neighbour becomes -1. color_index
// is updated to match. Ids are ordered by colour, then by the components' raster order.
Components color_components(cv::Mat1i& color_index, int palette_size, int min_area_px);

// Removes palette entries no pixel uses and renumbers color_index to match. Returns the map
// old index -> new index (-1 = dropped).
std::vector<int> drop_unused_colors(Palette& palette, cv::Mat1i& color_index);

}  // namespace atelier::embroidery
