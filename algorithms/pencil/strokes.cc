#include "algorithms/pencil/strokes.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

namespace atelier::pencil {

namespace {

// A 16-grey-level step under the 3x3 Sobel (weights 1, 2, 1 on each side): gradients below this
// are paper grain and JPEG noise, not edges.
constexpr double kNoiseFloor = 4.0 * 16.0;
// The automatic high threshold is half the median strong gradient. Below the median, because on
// a crisp drawing every edge's ridge pixels have the same magnitude -- the median -- and
// cv::Canny keeps only pixels strictly above its high threshold; half, because a drawing's
// crisp black-on-white edges set the median and its softer colour edges must still pass (pic5's
// green on navy, a 78-level step in one channel, peaks at ~300 against a median of ~410).
constexpr double kBelowMedian = 0.5;

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

void validate(const StrokeParams& p) {
  require(p.smoothing_px >= 0, "smoothing_px must be >= 0");
  require(std::isfinite(p.smoothing_sigma) && p.smoothing_sigma > 0, "smoothing_sigma must be > 0");
  require(std::isfinite(p.canny_low) && p.canny_low >= 0, "canny_low must be >= 0");
  require(std::isfinite(p.canny_high) && p.canny_high >= 0, "canny_high must be >= 0");
  require(p.canny_high > 0 || p.canny_low == 0, "canny_high must be > 0 when canny_low is set");
  require(p.canny_low <= p.canny_high, "canny_low must be <= canny_high");
  require(std::isfinite(p.simplify_px) && p.simplify_px >= 0, "simplify_px must be >= 0");
  require(std::isfinite(p.merge_angle_deg) && p.merge_angle_deg >= 0 && p.merge_angle_deg <= 180,
          "merge_angle_deg must be in [0, 180]");
  require(std::isfinite(p.merge_offset_px) && p.merge_offset_px >= 0, "merge_offset_px must be >= 0");
  require(std::isfinite(p.min_stroke_px) && p.min_stroke_px >= 0, "min_stroke_px must be >= 0");
  require(std::isfinite(p.max_stroke_px) && p.max_stroke_px >= 0, "max_stroke_px must be >= 0");
  require(p.max_stroke_px == 0 || p.max_stroke_px >= 2 * p.min_stroke_px,
          "max_stroke_px must be 0 or >= 2 * min_stroke_px");
}

double angle_deg(cv::Point2d a, cv::Point2d b) {
  const double na = std::hypot(a.x, a.y), nb = std::hypot(b.x, b.y);
  if (na == 0 || nb == 0) return 0;
  return std::acos(std::clamp(a.dot(b) / (na * nb), -1.0, 1.0)) * 180.0 / CV_PI;
}

// Distance of p from the segment a-b.
double to_segment(cv::Point2d p, cv::Point2d a, cv::Point2d b) {
  const cv::Point2d d = b - a;
  const double len2 = d.dot(d);
  const double t = len2 > 0 ? std::clamp((p - a).dot(d) / len2, 0.0, 1.0) : 0.0;
  const cv::Point2d q = a + t * d;
  return std::hypot(p.x - q.x, p.y - q.y);
}

// Step 0 of edge_strokes: removes the "simple" pixels of the edges (Yokoi's 8-connectivity
// number is 1: taking the pixel away neither splits an edge nor opens a hole) that are not line
// ends, in raster order until none is left. This leaves edges 8-connected and 1 px wide, with no
// 4-connected staircase pairs, so a border walk comes back over the very pixels it went out on.
void thin_edges(cv::Mat1b& edges) {
  // Neighbours in Yokoi's order: E, NE, N, NW, W, SW, S, SE.
  static constexpr int kDx[8] = {1, 1, 0, -1, -1, -1, 0, 1}, kDy[8] = {0, -1, -1, -1, 0, 1, 1, 1};
  for (bool changed = true; changed;) {
    changed = false;
    for (int y = 0; y < edges.rows; ++y)
      for (int x = 0; x < edges.cols; ++x) {
        if (!edges(y, x)) continue;
        int bg[8], neighbours = 0;
        for (int k = 0; k < 8; ++k) {
          const int nx = x + kDx[k], ny = y + kDy[k];
          const bool on = nx >= 0 && ny >= 0 && nx < edges.cols && ny < edges.rows && edges(ny, nx);
          bg[k] = on ? 0 : 1;
          neighbours += on;
        }
        int connectivity = 0;
        for (int k = 0; k < 8; k += 2) connectivity += bg[k] - bg[k] * bg[(k + 1) % 8] * bg[(k + 2) % 8];
        if (neighbours >= 2 && connectivity == 1) edges(y, x) = 0, changed = true;
      }
  }
}

// Step 2 of edge_strokes: cuts each walk into polylines of not yet visited pixels.
std::vector<std::vector<cv::Point>> unvisited_polylines(const std::vector<std::vector<cv::Point>>& walks,
                                                        cv::Size size) {
  cv::Mat1b visited(size, 0);
  std::vector<std::vector<cv::Point>> out;
  for (const auto& walk : walks) {
    const size_t n = walk.size();
    std::vector<cv::Point> cur;
    // Ends a polyline at `p` (a visited pixel) unless p is the pixel it just came from.
    auto close_at = [&](cv::Point p) {
      if (!(cur.size() >= 2 && cur[cur.size() - 2] == p) && cur.back() != p) cur.push_back(p);
      out.push_back(std::move(cur));
      cur.clear();
    };
    for (size_t i = 0; i < n; ++i) {
      const cv::Point p = walk[i];
      if (!visited(p)) {
        if (cur.empty() && n > 1) {
          const cv::Point prev = walk[(i + n - 1) % n];
          if (visited(prev) && prev != p) cur.push_back(prev);
        }
        cur.push_back(p);
        visited(p) = 1;
      } else if (!cur.empty()) {
        close_at(p);
      }
    }
    if (!cur.empty()) close_at(walk[0]);  // the walk comes round to its first pixel
  }
  return out;
}

// Step 3: Douglas-Peucker on one polyline. A closed one (first pixel = last) is simplified as a
// closed curve, so that where the walk happened to start is no vertex; a nearly closed one is
// split at its far point first.
std::vector<cv::Point2d> simplify(const std::vector<cv::Point>& line, double epsilon) {
  std::vector<cv::Point> out;
  if (line.size() > 3 && line.front() == line.back()) {
    cv::approxPolyDP(std::vector<cv::Point>(line.begin(), line.end() - 1), out, epsilon, true);
    if (out.size() >= 2) {
      std::vector<cv::Point2d> vertices(out.begin(), out.end());
      vertices.push_back(vertices.front());
      return vertices;
    }
    out.clear();
  }
  size_t far = 0;
  double far_dist = 0;
  for (size_t i = 0; i < line.size(); ++i) {
    const double d = cv::norm(line[i] - line.front());
    if (d > far_dist) far_dist = d, far = i;
  }
  const double ends = cv::norm(line.back() - line.front());
  if (ends < 0.5 * far_dist && far > 0 && far + 1 < line.size()) {
    const std::vector<cv::Point> first(line.begin(), line.begin() + far + 1), second(line.begin() + far, line.end());
    std::vector<cv::Point> a, b;
    cv::approxPolyDP(first, a, epsilon, false);
    cv::approxPolyDP(second, b, epsilon, false);
    out = a;
    out.insert(out.end(), b.begin() + 1, b.end());
  } else {
    cv::approxPolyDP(line, out, epsilon, false);
  }
  std::vector<cv::Point2d> vertices;
  for (const cv::Point& p : out)
    if (vertices.empty() || vertices.back() != cv::Point2d(p)) vertices.emplace_back(p);
  return vertices;
}

// Step 4: merges consecutive nearly collinear segments of one polyline into strokes.
void merge_into(const std::vector<cv::Point2d>& v, const StrokeParams& p, std::vector<Segment>& strokes) {
  size_t i = 0;
  while (i + 1 < v.size()) {
    size_t j = i + 1;  // the stroke is v[i] -> v[j]
    while (j + 1 < v.size()) {
      // How far the stroke turns by taking the segment in (not the segment's own direction: a
      // staircase's 1 px steps point 45 degrees off, however straight the edge).
      if (angle_deg(v[j] - v[i], v[j + 1] - v[i]) >= p.merge_angle_deg) break;
      bool close = true;
      for (size_t k = i + 1; k <= j && close; ++k) close = to_segment(v[k], v[i], v[j + 1]) <= p.merge_offset_px;
      if (!close) break;
      ++j;
    }
    strokes.push_back({v[i], v[j]});
    i = j;
  }
}

}  // namespace

cv::Mat on_white_paper(const cv::Mat& image) {
  require(!image.empty(), "image is empty");
  const int type = image.type();
  require(type == CV_8UC1 || type == CV_8UC3 || type == CV_8UC4, "image must be CV_8UC1, CV_8UC3 or CV_8UC4");
  if (type != CV_8UC4) return image;
  cv::Mat bgr(image.size(), CV_8UC3);
  for (int y = 0; y < image.rows; ++y) {
    const cv::Vec4b* in = image.ptr<cv::Vec4b>(y);
    cv::Vec3b* out = bgr.ptr<cv::Vec3b>(y);
    for (int x = 0; x < image.cols; ++x) {
      const int a = in[x][3];
      for (int c = 0; c < 3; ++c) out[x][c] = static_cast<uchar>((in[x][c] * a + 255 * (255 - a) + 127) / 255);
    }
  }
  return bgr;
}

cv::Vec2d auto_canny_thresholds(const cv::Mat& smoothed) {
  require(smoothed.type() == CV_8UC1 || smoothed.type() == CV_8UC3, "image must be CV_8UC1 or CV_8UC3");
  // In bands of rows: whole-image float gradients of a 40 Mpx colour image are 1.4 GB. A band
  // is a view into the image, so Sobel reads the rows above and below it from the image itself
  // (replicating only at the image's own edges): the same values as one whole-image pass.
  constexpr int kBandRows = 256;
  const int channels = smoothed.channels();
  std::vector<float> strong;
  cv::Mat dx, dy, mag;
  for (int y0 = 0; y0 < smoothed.rows; y0 += kBandRows) {
    const cv::Mat band = smoothed.rowRange(y0, std::min(smoothed.rows, y0 + kBandRows));
    cv::Sobel(band, dx, CV_32F, 1, 0, 3, 1, 0, cv::BORDER_REPLICATE);
    cv::Sobel(band, dy, CV_32F, 0, 1, 3, 1, 0, cv::BORDER_REPLICATE);
    cv::magnitude(dx.reshape(1), dy.reshape(1), mag);  // one column per channel
    for (int y = 0; y < mag.rows; ++y) {
      const float* row = mag.ptr<float>(y);
      for (int x = 0; x < band.cols; ++x) {
        float m = 0;
        for (int c = 0; c < channels; ++c) m = std::max(m, row[x * channels + c]);
        if (m > kNoiseFloor) strong.push_back(m);
      }
    }
  }
  double high = 2 * kNoiseFloor;
  if (!strong.empty()) {
    auto mid = strong.begin() + static_cast<std::ptrdiff_t>(strong.size() / 2);
    std::nth_element(strong.begin(), mid, strong.end());
    high = std::max(high, kBelowMedian * static_cast<double>(*mid));
  }
  return {high / 2, high};
}

cv::Mat edge_map(const cv::Mat& image, const StrokeParams& params) {
  validate(params);
  const cv::Mat paper = on_white_paper(image);
  try {
    cv::Mat smooth;  // a new buffer: bilateralFilter cannot work in place
    if (params.smoothing_px == 0)
      smooth = paper;
    else
      cv::bilateralFilter(paper, smooth, params.smoothing_px, params.smoothing_sigma, params.smoothing_px / 2.0,
                          cv::BORDER_REPLICATE);
    cv::Vec2d t(params.canny_low, params.canny_high);
    if (params.canny_high == 0) t = auto_canny_thresholds(smooth);
    cv::Mat edges;
    cv::Canny(smooth, edges, t[0], t[1], 3, true);
    return edges;
  } catch (const cv::Exception& e) {
    throw std::runtime_error(std::string("edge_map: OpenCV failed: ") + e.what());
  }
}

std::vector<Segment> edge_strokes(const cv::Mat& image, const StrokeParams& params) {
  cv::Mat1b edges = edge_map(image, params);
  thin_edges(edges);
  std::vector<std::vector<cv::Point>> walks;
  try {
    cv::findContours(edges, walks, cv::RETR_LIST, cv::CHAIN_APPROX_NONE);
  } catch (const cv::Exception& e) {
    throw std::runtime_error(std::string("edge_strokes: OpenCV failed: ") + e.what());
  }
  // Longest walks first: an outer walk claims its pixels before the small holes inside a
  // doubled edge can cut it into pieces; and a hand draws the big shapes before the details.
  std::stable_sort(walks.begin(), walks.end(), [](const auto& a, const auto& b) { return a.size() > b.size(); });
  std::vector<Segment> merged;
  for (const auto& line : unvisited_polylines(walks, edges.size())) {
    if (line.size() < 2) continue;
    merge_into(simplify(line, params.simplify_px), params, merged);
  }
  std::vector<Segment> strokes;
  for (const Segment& s : merged) {
    const double len = cv::norm(s.to - s.from);
    if (len < params.min_stroke_px || len == 0) continue;
    const int pieces = params.max_stroke_px > 0 ? static_cast<int>(std::ceil(len / params.max_stroke_px)) : 1;
    for (int k = 0; k < pieces; ++k)
      strokes.push_back({s.from + (s.to - s.from) * (static_cast<double>(k) / pieces),
                         s.from + (s.to - s.from) * (static_cast<double>(k + 1) / pieces)});
  }
  return strokes;
}

}  // namespace atelier::pencil
