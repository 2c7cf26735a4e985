// Paper section 4: the stroke width transform (Epshtein, Ofek and Wexler 2010) on the contour
// pixels of one single-colour component, and the n^0.8 rule that sends a component whose
// widths cannot be measured to the long-short stitch.
// Units: image pixels. Pure; thread-safe.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace atelier::embroidery {

struct StrokeWidths {
  std::vector<cv::Point> contour;  // contour pixels (mask coordinates), raster order: component
                                   // pixels with a 4-neighbour outside the component
  std::vector<float> width;        // per contour pixel: stroke width in pixels (>= 1), or 0 when
                                   // the pairing test failed
  int failures = 0;                // contour pixels with width 0
};

// mask: CV_8U, non-zero = the component (the caller's bounding box of it). origin: the mask's
// top-left pixel in the image; image: the image size. Contour pixels on the image border fail
// (the shape continues beyond what we see). Every other contour pixel p casts a ray along its
// inward gradient (Sobel of the mask smoothed by a 3x3 Gaussian) until the ray leaves the
// component; the last pixel q inside must be a contour pixel whose gradient points back within
// pi/6 of the opposite direction. Width = |p - q| + 1, so a stroke n pixels wide measures n.
// Where the component is one pixel thin (both left and right, or both up and down neighbours
// outside) and the gradient vanishes or the ray leaves at once, the width is 1.
StrokeWidths stroke_widths(const cv::Mat1b& mask, cv::Point origin, cv::Size image);

// The paper's threshold: more than n^0.8 failed pixels (n = the component's pixel count) and
// the whole component is sewn long-short.
bool swt_forces_long_short(int failures, int area_px);

}  // namespace atelier::embroidery
