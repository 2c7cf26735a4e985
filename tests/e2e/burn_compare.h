// Comparing what the laser emulator burned with what an SVG drew (shared by the cut and
// parquetry end-to-end tests). Masks are CV_8U, 255 = stroke or burn.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>

namespace atelier::test {

// Draws every stroked path of `svg` into `mask`, 1 px wide, at `px_per_mm` (SVG mm scaled:
// the emulator's render of a job placed at the bed's rear-left corner).
void draw_strokes(const std::filesystem::path& svg, double px_per_mm, cv::Mat& mask);

// Share of the set pixels of `a` that lie within `tolerance_px` of a set pixel of `b`.
double covered(const cv::Mat& a, const cv::Mat& b, int tolerance_px);

}  // namespace atelier::test
