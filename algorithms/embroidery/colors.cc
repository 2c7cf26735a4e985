#include "algorithms/embroidery/colors.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <queue>
#include <stdexcept>
#include <string>

namespace atelier::embroidery {
namespace {

constexpr int kMaxSamples = 8000;
constexpr long kPatchPixels = 160000;
constexpr int kMaxReplacements = 3;
// A thin line (too thin for a patch) this far from its cluster's centre, in more than 0.5 % of
// the samples, asks for another cluster: more than half the distance from black to white, so
// the blur between two colours never does.
constexpr double kFarDe = 50;
constexpr uint64_t kSeed = 0x5eed'e3b0'1dULL;

void check(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("colour extraction: " + what);
}

float dist2(const cv::Vec3f& a, const cv::Vec3f& b) {
  const cv::Vec3f d = a - b;
  return d.dot(d);
}

// cv::kmeans draws from cv::theRNG(); seed it for this call only and put the caller's state
// back, so the palette is reproducible and nobody else's random stream changes.
double kmeans_seeded(const cv::Mat& samples, int k, cv::Mat& labels, cv::Mat& centers) {
  cv::RNG& rng = cv::theRNG();
  const uint64_t saved = rng.state;
  rng.state = kSeed;
  const double compactness =
      cv::kmeans(samples, k, labels, cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 20, 0.05),
                 1, cv::KMEANS_PP_CENTERS, centers);
  rng.state = saved;
  return compactness;
}

// The automatic rule: every cluster of at least 1 % of the samples has half of them within
// dE delta_e of its centre (so two flat colours 23 apart in similar amounts are never one
// thread; an uneven mix leaves the minority far from the centre, and add_distinct_patches
// separates it), and at most 0.5 % of all samples lie farther than far_de from their centre
// (a thin black line on a white sheet barely moves any centre, yet it must get its own
// thread). The median, not the mean: the anti-aliased edge of thin white letters is a large
// share of their pixels but not a colour of its own.
bool clusters_hold(const cv::Mat& samples, const cv::Mat& labels, const cv::Mat& centers, double delta_e,
                   double far_de) {
  const int K = centers.rows;
  std::vector<std::vector<float>> dist(K);
  int far = 0;
  const float far2 = static_cast<float>(far_de * far_de);
  for (int i = 0; i < samples.rows; ++i) {
    const int k = labels.at<int>(i);
    const float d2 = dist2(samples.at<cv::Vec3f>(i), centers.at<cv::Vec3f>(k));
    dist[k].push_back(d2);
    far += d2 > far2;
  }
  for (std::vector<float>& d : dist) {
    if (d.empty() || static_cast<long>(d.size()) * 100 < samples.rows) continue;
    auto mid = d.begin() + static_cast<long>(d.size() / 2);
    std::nth_element(d.begin(), mid, d.end());
    if (*mid > delta_e * delta_e) return false;
  }
  return far * 200 <= samples.rows;
}

// Nearest centre of every pixel with mask != 0 (others -1), and optionally its squared
// distance. Parallel over rows.
void assign(const cv::Mat3f& lab, const cv::Mat1b& opaque, const std::vector<cv::Vec3f>& centre,
            cv::Mat1i& index, cv::Mat1f* d2 = nullptr) {
  const int W = lab.cols, H = lab.rows, K = static_cast<int>(centre.size());
  index.create(H, W);
  if (d2) d2->create(H, W);
  cv::parallel_for_(cv::Range(0, H), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const cv::Vec3f* l = lab[y];
      const uchar* a = opaque[y];
      int* o = index[y];
      float* dd = d2 ? (*d2)[y] : nullptr;
      for (int x = 0; x < W; ++x) {
        if (!a[x] || K == 0) {
          o[x] = -1;
          if (dd) dd[x] = 0;
          continue;
        }
        int best = 0;
        float bd = dist2(l[x], centre[0]);
        for (int k = 1; k < K; ++k) {
          const float d = dist2(l[x], centre[k]);
          if (d < bd) bd = d, best = k;
        }
        o[x] = best;
        if (dd) dd[x] = bd;
      }
    }
  });
}

// Per colour: the sum of lab over its pixels and their count.
void colour_sums(const cv::Mat1i& index, const cv::Mat3f& lab, int K, std::vector<cv::Vec3d>& sum,
                 std::vector<long>& count) {
  sum.assign(K, cv::Vec3d(0, 0, 0));
  count.assign(K, 0);
  for (int y = 0; y < index.rows; ++y) {
    const int* c = index[y];
    const cv::Vec3f* l = lab[y];
    for (int x = 0; x < index.cols; ++x)
      if (c[x] >= 0 && c[x] < K) {
        sum[c[x]] += cv::Vec3d(l[x][0], l[x][1], l[x][2]);
        ++count[c[x]];
      }
  }
}

// Pixel counts per centre (for weighted merges).
std::vector<long> centre_counts(const cv::Mat3f& lab, const cv::Mat1b& opaque, const std::vector<cv::Vec3f>& centre) {
  cv::Mat1i index;
  assign(lab, opaque, centre, index);
  std::vector<cv::Vec3d> sum;
  std::vector<long> count;
  colour_sums(index, lab, static_cast<int>(centre.size()), sum, count);
  return count;
}

// Replaces centres i and j by their count-weighted mean.
void merge_pair(std::vector<cv::Vec3f>& centre, std::vector<long>& count, size_t i, size_t j) {
  const double wi = static_cast<double>(std::max(1L, count[i])), wj = static_cast<double>(std::max(1L, count[j]));
  centre[i] = (centre[i] * wi + centre[j] * wj) * (1.0 / (wi + wj));
  count[i] += count[j];
  centre.erase(centre.begin() + static_cast<long>(j));
  count.erase(count.begin() + static_cast<long>(j));
}

// The closest pair of centres; returns its squared distance (infinity for fewer than two).
float closest_pair(const std::vector<cv::Vec3f>& centre, size_t& bi, size_t& bj) {
  float best = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < centre.size(); ++i)
    for (size_t j = i + 1; j < centre.size(); ++j) {
      const float d = dist2(centre[i], centre[j]);
      if (d < best) best = d, bi = i, bj = j;
    }
  return best;
}

// Distinct small colours (the second stage of the automatic rule). k-means on a subsample
// sees a 3 mm^2 highlight as a handful of samples and folds it into its neighbour's thread;
// here every pixel counts. A patch is an 8-connected piece of the pixels farther than
// distinct_de from every centre that survives a morphological opening (boundary pixels
// between two colours, which take in-between values, form lines thinner than that), has at
// least min_area_px (the caller passes 2 x the smallest region) and is one colour: its pixels within a mean dE of delta_e of their mean
// (a blurred edge or a shading ramp is not a thread; its ends belong to the threads beside
// it). The largest such patch becomes a thread (its mean colour); at most 2 x max_colors
// rounds. `lab` and `opaque` may be a reduced image, min_area_px scaled to it.
void add_distinct_patches(const cv::Mat3f& lab, const cv::Mat1b& opaque, std::vector<cv::Vec3f>& centre,
                          const ColorParams& p, int min_area_px) {
  const float distinct2 = static_cast<float>(p.distinct_delta_e * p.distinct_delta_e);
  // Opening radius: a disk of min_area_px survives it; boundary lines of 2-3 px do not.
  const int r = std::clamp(static_cast<int>(std::sqrt(min_area_px / CV_PI) / 2), 1, 3);
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * r + 1, 2 * r + 1});
  int replaced = 0;
  for (int round = 0; round < 2 * p.max_colors; ++round) {
    cv::Mat1i index;
    cv::Mat1f d2;
    assign(lab, opaque, centre, index, &d2);
    cv::Mat1b far = (d2 > distinct2) & opaque;
    if (cv::countNonZero(far) < min_area_px) return;
    cv::morphologyEx(far, far, cv::MORPH_OPEN, kernel);
    cv::Mat1i cc;
    cv::Mat stats, centroids;
    const int n = cv::connectedComponentsWithStats(far, cc, stats, centroids, 8, CV_32S);
    // Mean colour and spread of every patch large enough (two passes over its pixels).
    std::vector<cv::Vec3d> sum(n, cv::Vec3d(0, 0, 0));
    std::vector<double> spread(n, 0);
    auto big = [&](int i) { return i > 0 && stats.at<int>(i, cv::CC_STAT_AREA) >= min_area_px; };
    bool any = false;
    for (int i = 1; i < n; ++i) any |= big(i);
    if (!any) return;
    for (int y = 0; y < cc.rows; ++y)
      for (int x = 0; x < cc.cols; ++x)
        if (const int i = cc(y, x); big(i)) sum[i] += cv::Vec3d(lab(y, x)[0], lab(y, x)[1], lab(y, x)[2]);
    std::vector<cv::Vec3f> mean(n);
    for (int i = 1; i < n; ++i)
      if (big(i)) mean[i] = cv::Vec3f(sum[i] * (1.0 / stats.at<int>(i, cv::CC_STAT_AREA)));
    for (int y = 0; y < cc.rows; ++y)
      for (int x = 0; x < cc.cols; ++x)
        if (const int i = cc(y, x); big(i)) spread[i] += std::sqrt(dist2(lab(y, x), mean[i]));
    int best = -1;
    for (int i = 1; i < n; ++i) {
      if (!big(i) || spread[i] > p.auto_delta_e * stats.at<int>(i, cv::CC_STAT_AREA)) continue;
      float nearest = std::numeric_limits<float>::infinity();
      for (const cv::Vec3f& c : centre) nearest = std::min(nearest, dist2(mean[i], c));
      if (nearest <= distinct2) continue;  // a mix of colours already there: nothing new
      if (best < 0 || stats.at<int>(i, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA)) best = i;
    }
    if (best < 0) return;
    const cv::Vec3f colour = mean[best];
    float nearest = std::numeric_limits<float>::infinity();
    for (const cv::Vec3f& c : centre) nearest = std::min(nearest, dist2(colour, c));
    if (static_cast<int>(centre.size()) >= p.max_colors) {
      // Two threads closer to each other than this colour is to any: they become one. At most
      // kMaxReplacements times: each merge may leave pixels far from the merged thread.
      size_t i = 0, j = 0;
      if (replaced >= kMaxReplacements || closest_pair(centre, i, j) >= nearest) return;
      ++replaced;
      std::vector<long> count = centre_counts(lab, opaque, centre);
      merge_pair(centre, count, i, j);
    }
    centre.push_back(colour);
    // No Lloyd step here: it would pull a barely distinct patch colour back towards its big
    // neighbours and the patch would come back next round. The threads become the means of
    // their pixels at the end.
  }
}

// Threads within dE 5 of each other are one (a duplicate k-means centre in a flat colour);
// at most K - 1 merges.
void merge_close(const cv::Mat3f& lab, const cv::Mat1b& opaque, std::vector<cv::Vec3f>& centre) {
  size_t i = 0, j = 0;
  if (closest_pair(centre, i, j) >= 25.f) return;
  std::vector<long> count = centre_counts(lab, opaque, centre);
  while (centre.size() > 1 && closest_pair(centre, i, j) < 25.f) merge_pair(centre, count, i, j);
}

}  // namespace

void validate_color_params(const ColorParams& p) {
  check(p.median_ksize >= 1 && p.median_ksize % 2 == 1 && p.median_ksize <= 255,
        "median_ksize must be odd and in [1, 255]");
  check(p.max_colors >= 1 && p.max_colors <= 64, "max_colors must be in [1, 64]");
  check(p.colors >= 0 && p.colors <= p.max_colors, "colors must be 0 (automatic) or in [1, max_colors]");
  check(std::isfinite(p.auto_delta_e) && p.auto_delta_e > 0, "auto_delta_e must be > 0");
  check(std::isfinite(p.distinct_delta_e) && p.distinct_delta_e > 0, "distinct_delta_e must be > 0");
  check(p.min_area_px >= 1, "min_area_px must be >= 1");
}

void set_palette_to_means(Palette& palette, const cv::Mat1i& color_index, const cv::Mat3f& lab) {
  const int K = static_cast<int>(palette.lab.size());
  std::vector<cv::Vec3d> sum;
  std::vector<long> count;
  colour_sums(color_index, lab, K, sum, count);
  for (int k = 0; k < K; ++k)
    if (count[k] > 0)
      palette.lab[k] = cv::Vec3f(static_cast<float>(sum[k][0] / count[k]), static_cast<float>(sum[k][1] / count[k]),
                                 static_cast<float>(sum[k][2] / count[k]));
  palette.bgr.clear();
  if (K == 0) return;
  cv::Mat lab_row(1, K, CV_32FC3, palette.lab.data()), bgr_row;
  cv::cvtColor(lab_row, bgr_row, cv::COLOR_Lab2BGR);
  for (int k = 0; k < K; ++k) {
    const cv::Vec3f c = bgr_row.at<cv::Vec3f>(0, k) * 255.0f;
    palette.bgr.emplace_back(cv::saturate_cast<uchar>(c[0]), cv::saturate_cast<uchar>(c[1]),
                             cv::saturate_cast<uchar>(c[2]));
  }
}

ColorExtraction extract_colors(const cv::Mat& image, const ColorParams& p) {
  check(!image.empty(), "empty image");
  check(image.type() == CV_8UC3 || image.type() == CV_8UC4, "image must be CV_8UC3 or CV_8UC4");
  validate_color_params(p);
  const int W = image.cols, H = image.rows;
  cv::Mat bgr;
  cv::Mat1b opaque;
  if (image.channels() == 4) {
    cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
    cv::Mat alpha;
    cv::extractChannel(image, alpha, 3);
    opaque = alpha >= 128;
  } else {
    bgr = image;
    opaque = cv::Mat1b(H, W, uchar(255));
  }
  const long total = static_cast<long>(W) * H;
  const long opaque_count = cv::countNonZero(opaque);
  // An opaque RGBA image is the same picture as its RGB: only a transparent pixel makes
  // transparency the background.
  const bool any_transparent = opaque_count < total;
  cv::Mat filtered;
  if (p.median_ksize > 1) cv::medianBlur(bgr, filtered, p.median_ksize);
  else filtered = bgr;
  cv::Mat f32;
  filtered.convertTo(f32, CV_32F, 1.0 / 255.0);
  ColorExtraction out;
  cv::cvtColor(f32, out.lab, cv::COLOR_BGR2Lab);  // L in [0, 100]
  const cv::Mat3f& lab3 = out.lab;

  out.color_index.create(H, W);
  if (opaque_count == 0) {
    out.color_index.setTo(-1);
    return out;
  }
  // Fixed-seed subsample of opaque pixels (a local RNG: no global state touched).
  cv::Mat samples;
  if (opaque_count <= kMaxSamples) {
    samples.create(static_cast<int>(opaque_count), 1, CV_32FC3);
    int n = 0;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x)
        if (opaque(y, x)) samples.at<cv::Vec3f>(n++) = lab3(y, x);
  } else {
    samples.create(kMaxSamples, 1, CV_32FC3);
    cv::RNG rng(kSeed);
    // Opaque pixels are more than kMaxSamples of the image; the draw is bounded by taking
    // them in raster order once the random draws have had 64 x kMaxSamples tries.
    int n = 0;
    for (long tries = 0; n < kMaxSamples && tries < 64L * kMaxSamples; ++tries) {
      const long i = static_cast<long>(rng.uniform(0.0, static_cast<double>(total)));
      const int y = static_cast<int>(i / W), x = static_cast<int>(i % W);
      if (opaque(y, x)) samples.at<cv::Vec3f>(n++) = lab3(y, x);
    }
    const long step = std::max(1L, opaque_count / kMaxSamples);
    long seen = 0;
    for (int y = 0; y < H && n < kMaxSamples; ++y)
      for (int x = 0; x < W && n < kMaxSamples; ++x)
        if (opaque(y, x) && seen++ % step == 0) samples.at<cv::Vec3f>(n++) = lab3(y, x);
    samples = samples.rowRange(0, n);
  }

  cv::Mat labels, centers;
  std::vector<cv::Vec3f> centre;
  if (p.colors > 0) {
    kmeans_seeded(samples, std::min(p.colors, samples.rows), labels, centers);
    for (int i = 0; i < centers.rows; ++i) centre.push_back(centers.at<cv::Vec3f>(i));
  } else {
    // Automatic: the smallest k that holds the colours (at most max_colors k-means runs).
    // Every k in turn, not a bisection: holding is not monotone in k (LinuxLogo holds at 2,
    // not at 3, where a cluster of anti-aliased edge pixels appears).
    for (int k = 1; k <= std::min(p.max_colors, samples.rows); ++k) {
      kmeans_seeded(samples, k, labels, centers);
      if (clusters_hold(samples, labels, centers, p.auto_delta_e, kFarDe)) break;
    }
    for (int i = 0; i < centers.rows; ++i) centre.push_back(centers.at<cv::Vec3f>(i));
    // The distinct patches on an image of at most kPatchPixels (a 3 mm^2 patch at 10 px/mm
    // in a 100 mm design is still 48 px there): their search runs over every pixel, a few
    // times per round.
    const double shrink = std::min(1.0, std::sqrt(static_cast<double>(kPatchPixels) / static_cast<double>(total)));
    cv::Mat3f small_lab = lab3;
    cv::Mat1b small_opaque = opaque;
    if (shrink < 1.0) {
      const cv::Size size(std::max(1, static_cast<int>(W * shrink)), std::max(1, static_cast<int>(H * shrink)));
      cv::resize(lab3, small_lab, size, 0, 0, cv::INTER_AREA);
      cv::resize(opaque, small_opaque, size, 0, 0, cv::INTER_AREA);
      small_opaque = small_opaque >= 128;
    }
    const double area_scale = static_cast<double>(small_lab.total()) / static_cast<double>(total);
    // A thread of its own asks for twice the smallest region: a region of a colour that has
    // one is at least that (2 mm^2 by default), and a speck of JPEG noise never is.
    const int small_min_area = std::max(1, static_cast<int>(std::lround(2.0 * p.min_area_px * area_scale)));
    merge_close(small_lab, small_opaque, centre);
    add_distinct_patches(small_lab, small_opaque, centre, p, small_min_area);
    merge_close(small_lab, small_opaque, centre);
  }
  const int K = static_cast<int>(centre.size());

  // Every pixel to its nearest centre; the thread is then the mean of the pixels it sews.
  assign(lab3, opaque, centre, out.color_index);
  out.palette.lab = centre;
  set_palette_to_means(out.palette, out.color_index, lab3);

  // The fabric showing through: a near-white cluster holding most of the image border.
  if (p.background == Background::automatic && !any_transparent) {
    std::vector<long> border(K, 0);
    long border_px = 0;
    auto count = [&](int y, int x) { ++border[out.color_index(y, x)], ++border_px; };
    for (int x = 0; x < W; ++x) {
      count(0, x);
      if (H > 1) count(H - 1, x);
    }
    for (int y = 1; y + 1 < H; ++y) {
      count(y, 0);
      if (W > 1) count(y, W - 1);
    }
    for (int k = 0; k < K; ++k) {
      const cv::Vec3f& c = out.palette.lab[k];
      const bool near_white = c[0] > 90 && std::hypot(c[1], c[2]) < 12;
      if (near_white && 2 * border[k] > border_px)
        out.color_index.setTo(-1, out.color_index == k);
    }
  }
  drop_unused_colors(out.palette, out.color_index);
  return out;
}

std::vector<int> drop_unused_colors(Palette& palette, cv::Mat1i& color_index) {
  const int K = static_cast<int>(palette.bgr.size());
  std::vector<char> used(K, 0);
  for (int y = 0; y < color_index.rows; ++y) {
    const int* c = color_index[y];
    for (int x = 0; x < color_index.cols; ++x)
      if (c[x] >= 0) used[c[x]] = 1;
  }
  std::vector<int> remap(K, -1);
  Palette kept;
  for (int k = 0; k < K; ++k)
    if (used[k]) {
      remap[k] = static_cast<int>(kept.bgr.size());
      kept.bgr.push_back(palette.bgr[k]);
      kept.lab.push_back(palette.lab[k]);
    }
  if (static_cast<int>(kept.bgr.size()) != K) {
    for (int y = 0; y < color_index.rows; ++y) {
      int* c = color_index[y];
      for (int x = 0; x < color_index.cols; ++x)
        if (c[x] >= 0) c[x] = remap[c[x]];
    }
  }
  palette = std::move(kept);
  return remap;
}

namespace {

// Labels the 4-connected components of every colour (each colour on its own bounding box,
// colours in parallel). Ids: colour by colour, raster order within a colour.
Components label_components(const cv::Mat1i& color_index, int palette_size) {
  const int W = color_index.cols, H = color_index.rows;
  std::vector<cv::Rect> cbox(palette_size);
  {
    std::vector<int> x0(palette_size, W), y0(palette_size, H), x1(palette_size, -1), y1(palette_size, -1);
    for (int y = 0; y < H; ++y) {
      const int* c = color_index[y];
      for (int x = 0; x < W; ++x) {
        const int k = c[x];
        if (k < 0) continue;
        x0[k] = std::min(x0[k], x), x1[k] = std::max(x1[k], x);
        y0[k] = std::min(y0[k], y), y1[k] = std::max(y1[k], y);
      }
    }
    for (int k = 0; k < palette_size; ++k)
      if (x1[k] >= 0) cbox[k] = cv::Rect(x0[k], y0[k], x1[k] - x0[k] + 1, y1[k] - y0[k] + 1);
  }
  std::vector<cv::Mat> lab(palette_size), stats(palette_size);
  cv::parallel_for_(cv::Range(0, palette_size), [&](const cv::Range& r) {
    for (int k = r.start; k < r.end; ++k) {
      if (cbox[k].empty()) continue;
      cv::Mat mask = color_index(cbox[k]) == k, centroids;
      cv::connectedComponentsWithStats(mask, lab[k], stats[k], centroids, 4, CV_32S);
    }
  });
  Components out;
  out.id.create(H, W);
  out.id.setTo(-1);
  std::vector<int> offset(palette_size, 0);
  for (int k = 0; k < palette_size; ++k) {
    offset[k] = static_cast<int>(out.color.size());
    if (cbox[k].empty()) continue;
    for (int i = 1; i < stats[k].rows; ++i) {
      const int* s = stats[k].ptr<int>(i);
      out.color.push_back(k);
      out.area_px.push_back(s[cv::CC_STAT_AREA]);
      out.bbox.emplace_back(s[cv::CC_STAT_LEFT] + cbox[k].x, s[cv::CC_STAT_TOP] + cbox[k].y,
                            s[cv::CC_STAT_WIDTH], s[cv::CC_STAT_HEIGHT]);
    }
  }
  cv::parallel_for_(cv::Range(0, palette_size), [&](const cv::Range& r) {
    for (int k = r.start; k < r.end; ++k) {
      if (cbox[k].empty()) continue;
      const cv::Mat1i l = lab[k];
      for (int y = 0; y < l.rows; ++y) {
        const int* s = l[y];
        int* d = out.id[y + cbox[k].y] + cbox[k].x;
        for (int x = 0; x < l.cols; ++x)
          if (s[x] > 0) d[x] = offset[k] + s[x] - 1;
      }
    }
  });
  return out;
}

}  // namespace

Components color_components(cv::Mat1i& color_index, int palette_size, int min_area_px) {
  Components c = label_components(color_index, palette_size);
  const int n = static_cast<int>(c.color.size());
  std::vector<char> small(n);
  bool any_small = false;
  for (int i = 0; i < n; ++i) any_small |= (small[i] = c.area_px[i] < min_area_px);
  if (!any_small) return c;

  // Shared border lengths of small components with their neighbours: (small, other) pairs.
  std::vector<std::pair<int, int>> touch;
  const int W = color_index.cols, H = color_index.rows;
  auto note = [&](int a, int b) {
    if (a == b || a < 0 || b < 0) return;
    if (small[a]) touch.emplace_back(a, b);
    if (small[b]) touch.emplace_back(b, a);
  };
  for (int y = 0; y < H; ++y) {
    const int* r = c.id[y];
    const int* d = y + 1 < H ? c.id[y + 1] : nullptr;
    for (int x = 0; x < W; ++x) {
      if (x + 1 < W) note(r[x], r[x + 1]);
      if (d) note(r[x], d[x]);
    }
  }
  std::sort(touch.begin(), touch.end());
  std::vector<std::vector<std::pair<int, int>>> nb(n);  // small component -> (neighbour, border)
  for (size_t i = 0; i < touch.size();) {
    size_t j = i;
    while (j < touch.size() && touch[j] == touch[i]) ++j;
    nb[touch[i].first].emplace_back(touch[i].second, static_cast<int>(j - i));
    i = j;
  }

  std::vector<int> parent(n), area = c.area_px, color = c.color;
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<char> dropped(n, 0);
  auto find = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  using Item = std::pair<int, int>;  // (area, id): smallest first, ties by id
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  for (int i = 0; i < n; ++i)
    if (small[i]) queue.emplace(area[i], i);
  while (!queue.empty()) {
    const auto [a, r] = queue.top();
    queue.pop();
    if (find(r) != r || dropped[r] || area[r] != a || area[r] >= min_area_px) continue;
    // Sum the border per current neighbour root.
    std::vector<std::pair<int, int>> sums;
    for (const auto& [other, len] : nb[r]) {
      const int o = find(other);
      if (o != r && !dropped[o]) sums.emplace_back(o, len);
    }
    std::sort(sums.begin(), sums.end());
    int best = -1, best_len = 0;
    for (size_t i = 0; i < sums.size();) {
      size_t j = i;
      int len = 0;
      while (j < sums.size() && sums[j].first == sums[i].first) len += sums[j++].second;
      if (len > best_len || (len == best_len && area[sums[i].first] > area[best]))
        best = sums[i].first, best_len = len;
      i = j;
    }
    if (best < 0) {
      dropped[r] = 1;
      continue;
    }
    parent[r] = best;
    area[best] += area[r];
    if (small[best]) {
      nb[best].insert(nb[best].end(), nb[r].begin(), nb[r].end());
      if (area[best] < min_area_px) queue.emplace(area[best], best);
    }
    nb[r].clear();
    nb[r].shrink_to_fit();
  }
  std::vector<int> final_color(n);
  for (int i = 0; i < n; ++i) {
    const int root = find(i);
    final_color[i] = dropped[root] ? -1 : color[root];
  }
  // Merged pieces may join components of one colour. Every such join involves a component
  // that was small (two others of one colour never touch: they would be one component, and
  // only small ones change colour), and `touch` holds every border of a small one; so joining
  // the touching pairs of equal final colour gives the components without labelling again.
  std::vector<int> join(n);
  std::iota(join.begin(), join.end(), 0);
  auto root = [&](int v) {
    while (join[v] != v) v = join[v] = join[join[v]];
    return v;
  };
  for (const auto& [a, b] : touch)
    if (final_color[a] >= 0 && final_color[a] == final_color[b]) {
      const int ra = root(a), rb = root(b);
      if (ra != rb) join[std::max(ra, rb)] = std::min(ra, rb);
    }
  // Each joined component's first pixel in raster order (a component's first pixel lies in
  // the top row of its box), to number them by colour, then raster order, as labelling would.
  std::vector<long> first(n, -1);
  for (int i = 0; i < n; ++i) {
    const int r = root(i);
    if (final_color[r] < 0) continue;
    const cv::Rect& b = c.bbox[i];
    const int* row = c.id[b.y];
    int x = b.x;
    while (row[x] != i) ++x;
    const long f = static_cast<long>(b.y) * W + x;
    if (first[r] < 0 || f < first[r]) first[r] = f;
  }
  std::vector<int> roots;
  for (int i = 0; i < n; ++i)
    if (root(i) == i && final_color[i] >= 0) roots.push_back(i);
  std::sort(roots.begin(), roots.end(), [&](int a, int b) {
    return final_color[a] != final_color[b] ? final_color[a] < final_color[b] : first[a] < first[b];
  });
  Components out;
  std::vector<int> new_id(n, -1);
  for (int r : roots) {
    new_id[r] = static_cast<int>(out.color.size());
    out.color.push_back(final_color[r]);
    out.area_px.push_back(0);
    out.bbox.emplace_back();
  }
  for (int i = 0; i < n; ++i) {
    const int r = root(i);
    if (final_color[r] < 0) continue;
    new_id[i] = new_id[r];
    out.area_px[new_id[i]] += c.area_px[i];
    cv::Rect& b = out.bbox[new_id[i]];
    b = b.empty() ? c.bbox[i] : (b | c.bbox[i]);
  }
  out.id = std::move(c.id);
  cv::parallel_for_(cv::Range(0, H), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      int* id = out.id[y];
      int* ci = color_index[y];
      for (int x = 0; x < W; ++x)
        if (id[x] >= 0) {
          ci[x] = final_color[id[x]];
          id[x] = new_id[id[x]];
        }
    }
  });
  return out;
}

}  // namespace atelier::embroidery
