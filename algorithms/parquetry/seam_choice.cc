#include "algorithms/parquetry/seam_choice.h"

#include <algorithm>
#include <cmath>

#include "algorithms/parquetry/quality.h"

namespace atelier::parquetry {

namespace {

// A run of steps [begin, end) along cut `line` of one direction.
struct Segment {
  bool vertical = true;
  int line = 0, begin = 0, end = 0;
};

// The runs of steps where `held` is 0 (outside every band of the other direction).
std::vector<Segment> segments(bool vertical, int line, const std::vector<char>& held) {
  std::vector<Segment> out;
  const int n = static_cast<int>(held.size());
  for (int k = 0; k < n;) {
    if (held[static_cast<std::size_t>(k)]) {
      ++k;
      continue;
    }
    int e = k;
    while (e < n && !held[static_cast<std::size_t>(e)]) ++e;
    out.push_back({vertical, line, k, e});
    k = e;
  }
  return out;
}

// The cut's steps of `seg` as a straight run between its positions just outside it: level
// with the one crossing where it meets a border, on the grid line `grid` where it runs from
// border to border.
std::vector<int> straight_run(const std::vector<int>& cut, const Segment& seg, int grid) {
  const int n = static_cast<int>(cut.size());
  const bool from_border = seg.begin == 0, to_border = seg.end == n;
  const double a = !from_border ? cut[static_cast<std::size_t>(seg.begin - 1)]
                   : !to_border ? cut[static_cast<std::size_t>(seg.end)] : grid;
  const double b = !to_border ? cut[static_cast<std::size_t>(seg.end)] : a;
  const double len = seg.end - seg.begin + 1;
  std::vector<int> run;
  for (int k = seg.begin; k < seg.end; ++k) {
    run.push_back(static_cast<int>(std::lround(a + (b - a) * (k - seg.begin + 1) / len)));
  }
  return run;
}

class Painter {
 public:
  Painter(const Seams& seams, const SeamInput& in, const std::vector<cv::Mat>& wood)
      : s_(seams), in_(in), wood_(wood) {
    for (int r = 0; r < in.rows; ++r)
      for (int c = 0; c < in.cols; ++c) win_.push_back(cell_window(in, c, r));
  }
  // The reconstruction over `roi` under the current seams.
  cv::Mat paint(const cv::Rect& roi) const {
    cv::Mat out(roi.size(), CV_8UC3);
    for (int y = roi.y; y < roi.y + roi.height; ++y) {
      for (int x = roi.x; x < roi.x + roi.width; ++x) {
        const int cell = row_of(x, y) * in_.cols + col_of(x, y);
        const cv::Rect& w = win_[static_cast<std::size_t>(cell)];
        out.at<cv::Vec3b>(y - roi.y, x - roi.x) = wood_[static_cast<std::size_t>(cell)].at<cv::Vec3b>(y - w.y, x - w.x);
      }
    }
    return out;
  }
  // Every pixel of `roi` comes from wood its cell may use.
  bool available(const cv::Rect& roi) const {
    if (in_.available.empty()) return true;
    for (int y = roi.y; y < roi.y + roi.height; ++y) {
      for (int x = roi.x; x < roi.x + roi.width; ++x) {
        const int cell = row_of(x, y) * in_.cols + col_of(x, y);
        const cv::Rect& w = win_[static_cast<std::size_t>(cell)];
        if (!in_.available[static_cast<std::size_t>(cell)].at<uchar>(y - w.y, x - w.x)) return false;
      }
    }
    return true;
  }

 private:
  int col_of(int x, int y) const { return side_index(s_.vertical, in_.pitch, in_.half, in_.cols, x, y); }
  int row_of(int x, int y) const { return side_index(s_.horizontal, in_.pitch, in_.half, in_.rows, y, x); }
  const Seams& s_;
  const SeamInput& in_;
  const std::vector<cv::Mat>& wood_;
  std::vector<cv::Rect> win_;
};

}  // namespace

SeamChoice choose_seams(Seams& seams, const SeamInput& in, const std::vector<cv::Mat>& wood_bgr,
                        const cv::Mat& target_bgr, double px_per_mm) {
  const int W = in.cols * in.pitch, H = in.rows * in.pitch;
  // Rows / columns where the other direction's cuts may pass (see Seams).
  std::vector<char> v_held(static_cast<std::size_t>(H), 0), h_held(static_cast<std::size_t>(W), 0);
  for (int j = 1; j < in.rows; ++j)
    for (int y = j * in.pitch - in.half - 1; y <= j * in.pitch + in.half; ++y) v_held[static_cast<std::size_t>(y)] = 1;
  for (int i = 1; i < in.cols; ++i)
    for (int x = i * in.pitch - in.half - 1; x <= i * in.pitch + in.half; ++x) h_held[static_cast<std::size_t>(x)] = 1;
  std::vector<Segment> all;
  for (int i = 1; i < in.cols; ++i) {
    for (const Segment& s : segments(true, i, v_held)) all.push_back(s);
  }
  for (int j = 1; j < in.rows; ++j) {
    for (const Segment& s : segments(false, j, h_held)) all.push_back(s);
  }

  const Painter painter(seams, in, wood_bgr);
  // A change moves the SSIM map up to `reach` px away; the crop's own border moves it as far,
  // so the crop reaches twice that beyond the change.
  const int margin = 2 * blurred_ssim_reach_px(px_per_mm) + 1;
  const cv::Rect result(0, 0, W, H);
  SeamChoice choice;
  for (const Segment& seg : all) {
    std::vector<int>& cut = seg.vertical ? seams.vertical[static_cast<std::size_t>(seg.line)]
                                         : seams.horizontal[static_cast<std::size_t>(seg.line)];
    const std::vector<int> straight = straight_run(cut, seg, seg.line * in.pitch);
    const std::vector<int> refined(cut.begin() + seg.begin, cut.begin() + seg.end);
    if (straight == refined) continue;
    // The pixels that may change: the band of the cut along the segment.
    const int lo = seg.line * in.pitch - in.half, across = 2 * in.half;
    const cv::Rect band = seg.vertical ? cv::Rect(lo, seg.begin, across, seg.end - seg.begin)
                                       : cv::Rect(seg.begin, lo, seg.end - seg.begin, across);
    const cv::Rect roi = cv::Rect(band.x - margin, band.y - margin, band.width + 2 * margin,
                                  band.height + 2 * margin) & result;
    const cv::Mat target = target_bgr(roi);
    const double before = cv::sum(blurred_ssim_map(painter.paint(roi), target, px_per_mm))[0];
    std::copy(straight.begin(), straight.end(), cut.begin() + seg.begin);
    const double after = cv::sum(blurred_ssim_map(painter.paint(roi), target, px_per_mm))[0];
    if (after > before && painter.available(band)) {
      ++choice.straightened;
    } else {
      std::copy(refined.begin(), refined.end(), cut.begin() + seg.begin);
      ++choice.kept;
    }
  }
  return choice;
}

}  // namespace atelier::parquetry
