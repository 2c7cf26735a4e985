#include "algorithms/embroidery/style_labels.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

namespace atelier::embroidery {
namespace {

double logistic_cost(double k, double exponent) { return k / (1.0 + std::exp(exponent)); }

// Islands (4-connected same-style pieces under min_area_px) take the style they share the most
// border with. One pass over the styles suffices: absorbing an island of style s only grows
// pieces of other styles (never leaves a new small piece), and every small piece of a style is
// absorbed on that style's turn, so a second pass would find nothing to change.
void absorb_islands(cv::Mat1b& style, const cv::Mat1b& mask, int min_area_px) {
  // One style alone has no islands (its only piece is the whole component): skip the scans.
  bool present[kStyleCount] = {false, false, false};
  for (int y = 0; y < style.rows; ++y) {
    const uchar* s = style[y];
    for (int x = 0; x < style.cols; ++x)
      if (s[x] < kStyleCount) present[s[x]] = true;
  }
  if (present[0] + present[1] + present[2] <= 1) return;
  for (int s = 0; s < kStyleCount; ++s) {
    // Label on the style's own bounding box (taken now: earlier styles' islands may have joined it).
    int x0 = style.cols, y0 = style.rows, x1 = -1, y1 = -1;
    for (int y = 0; y < style.rows; ++y) {
      const uchar* r = style[y];
      for (int x = 0; x < style.cols; ++x)
        if (r[x] == s) x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = y;
    }
    if (x1 < 0) continue;
    const cv::Rect sub(x0, y0, x1 - x0 + 1, y1 - y0 + 1);
    cv::Mat1b sm = style(sub) == s;
    cv::Mat1i lab_sub;
    cv::Mat stats, centroids;
    const int n = cv::connectedComponentsWithStats(sm, lab_sub, stats, centroids, 4, CV_32S);
    // Island boxes below are in the component's box; every island pixel lies inside sub.
    auto lab = [&](int y, int x) { return lab_sub(y - sub.y, x - sub.x); };
    for (int i = 1; i < n; ++i) {
      if (stats.at<int>(i, cv::CC_STAT_AREA) >= min_area_px) continue;
      const cv::Rect box = cv::Rect(stats.at<int>(i, cv::CC_STAT_LEFT), stats.at<int>(i, cv::CC_STAT_TOP),
                                    stats.at<int>(i, cv::CC_STAT_WIDTH), stats.at<int>(i, cv::CC_STAT_HEIGHT)) +
                           sub.tl();
      int border[kStyleCount] = {0, 0, 0};
      for (int y = box.y; y < box.br().y; ++y)
        for (int x = box.x; x < box.br().x; ++x) {
          if (lab(y, x) != i) continue;
          const cv::Point nb[4] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
          for (const cv::Point& q : nb)
            if (q.x >= 0 && q.y >= 0 && q.x < mask.cols && q.y < mask.rows && mask(q) &&
                style(q) != s)
              ++border[style(q)];
        }
      const int best = static_cast<int>(std::max_element(border, border + kStyleCount) - border);
      if (border[best] == 0) continue;  // the whole component: nothing to join
      for (int y = box.y; y < box.br().y; ++y)
        for (int x = box.x; x < box.br().x; ++x)
          if (lab(y, x) == i) style(y, x) = static_cast<uchar>(best);
    }
  }
}

// The block-level problem of a big component, built directly: exactly
// coarsen(style_problem(mask, widths, p).problem, blocks) as solve_styles(sp, max_cut_nodes)
// would build it (same groups, same sums, same sorted edges), without the full-resolution
// edge list. Only edges crossing a block boundary survive coarsening, so only block
// boundaries and the nearest-contour links are visited. group_of_block: block -> group, -1
// for blocks without a component pixel.
LabelProblem block_problem(const cv::Mat1b& mask, const StrokeWidths& widths, const LabelParams& p, int side,
                           std::vector<int>& group_of_block, int& bw) {
  bw = (mask.cols + side - 1) / side;
  const int bh = (mask.rows + side - 1) / side;
  group_of_block.assign(static_cast<size_t>(bw) * bh, -1);
  int groups = 0;
  for (int y = 0; y < mask.rows; ++y) {  // groups numbered by their first pixel in raster order
    const uchar* m = mask[y];
    int* row = &group_of_block[static_cast<size_t>(y / side) * bw];
    for (int x = 0; x < mask.cols; ++x)
      if (m[x] && row[x / side] < 0) row[x / side] = groups++;
  }
  auto group = [&](int x, int y) { return group_of_block[static_cast<size_t>(y / side) * bw + x / side]; };
  LabelProblem c;
  c.nodes = groups;
  c.labels = kStyleCount;
  c.unary.assign(static_cast<size_t>(groups) * kStyleCount, 0.0);
  c.distance.resize(kStyleCount * kStyleCount);
  for (int a = 0; a < kStyleCount; ++a)
    for (int b = 0; b < kStyleCount; ++b) c.distance[a * kStyleCount + b] = smooth_cost(Style(a), Style(b), p);
  c.label_cost.assign(p.label_cost, p.label_cost + kStyleCount);
  cv::Mat1b not_c(mask.size(), uchar(255));
  bool any_c = false;
  for (size_t i = 0; i < widths.contour.size(); ++i) {  // raster order, as the node order
    const float w = widths.width[i];
    if (w <= 0) continue;
    const cv::Point q = widths.contour[i];
    const int g = group(q.x, q.y);
    for (int s = 0; s < kStyleCount; ++s)
      c.unary[static_cast<size_t>(g) * kStyleCount + s] += data_cost(Style(s), w, p);
    not_c(q) = 0;
    any_c = true;
  }
  // (group pair, count) runs: neighbouring pixels mostly link the same two blocks, so counting
  // repeats as they come leaves far fewer entries to sort.
  std::vector<std::pair<std::uint64_t, int>> keys;
  auto link = [&](int ga, int gb) {
    if (ga == gb) return;
    const std::uint64_t a = static_cast<std::uint32_t>(ga), b = static_cast<std::uint32_t>(gb);
    const std::uint64_t key = std::min(a, b) << 32 | std::max(a, b);
    if (!keys.empty() && keys.back().first == key) ++keys.back().second;
    else keys.emplace_back(key, 1);
  };
  // 4-neighbours across a vertical block boundary (x, x + 1) and a horizontal one (y, y + 1).
  for (int y = 0; y < mask.rows; ++y) {
    const uchar* m = mask[y];
    for (int x = side - 1; x + 1 < mask.cols; x += side)
      if (m[x] && m[x + 1]) link(group(x, y), group(x + 1, y));
  }
  for (int y = side - 1; y + 1 < mask.rows; y += side) {
    const uchar *m = mask[y], *d = mask[y + 1];
    for (int x = 0; x < mask.cols; ++x)
      if (m[x] && d[x]) link(group(x, y), group(x, y + 1));
  }
  if (any_c) {
    cv::Mat dist;
    cv::Mat1i nearest;
    cv::distanceTransform(not_c, dist, nearest, cv::DIST_L2, 5, cv::DIST_LABEL_PIXEL);
    std::vector<int> c_group;  // label - 1 -> group of that contour pixel
    for (int y = 0; y < mask.rows; ++y)
      for (int x = 0; x < mask.cols; ++x)
        if (!not_c(y, x)) c_group.push_back(group(x, y));
    for (int y = 0; y < mask.rows; ++y) {
      const uchar *m = mask[y], *nc = not_c[y];
      const int* l = nearest[y];
      for (int x = 0; x < mask.cols; ++x) {
        if (!m[x] || !nc[x]) continue;
        if (l[x] < 1 || l[x] > static_cast<int>(c_group.size())) continue;
        link(group(x, y), c_group[l[x] - 1]);
      }
    }
  }
  std::sort(keys.begin(), keys.end());
  for (size_t i = 0; i < keys.size();) {
    size_t j = i;
    long count = 0;
    while (j < keys.size() && keys[j].first == keys[i].first) count += keys[j++].second;
    const std::uint64_t key = keys[i].first;
    c.edges.push_back({static_cast<int>(key >> 32), static_cast<int>(key & 0xffffffffu), static_cast<double>(count)});
    i = j;
  }
  return c;
}

}  // namespace

void validate_label_params(const LabelParams& p) {
  auto check = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("label parameters: ") + what);
  };
  check(std::isfinite(p.eW_px) && p.eW_px > 0, "eW_px must be > 0");
  check(std::isfinite(p.sW_px) && p.sW_px > p.eW_px, "sW_px must be > eW_px");
  for (double k : {p.k1, p.k2, p.k3, p.k4}) check(std::isfinite(k) && k >= 0, "k1..k4 must be >= 0");
  for (double c : p.label_cost) check(std::isfinite(c) && c >= 0, "label costs must be >= 0");
  check(p.max_cut_nodes >= 16, "max_cut_nodes must be >= 16");
}

double data_cost(Style style, double w, const LabelParams& p) {
  const double eW = p.eW_px, sW = p.sW_px;
  switch (style) {
    case Style::long_short: return logistic_cost(p.k1, (w - sW) / 2);                  // eq. 1
    case Style::satin:                                                                   // eq. 2
      return w >= sW ? logistic_cost(p.k1, (sW - w) / 2) : logistic_cost(p.k2, 2 * eW * (w - eW));
    case Style::edge: return logistic_cost(p.k2, 2 * eW * (eW - w));                    // eq. 3
  }
  return 0;
}

double smooth_cost(Style a, Style b, const LabelParams& p) {
  if (a == b) return 0;
  if (a == Style::edge || b == Style::edge) return p.k3;
  return p.k4;
}

StyleProblem style_problem(const cv::Mat1b& mask, const StrokeWidths& widths, const LabelParams& p) {
  validate_label_params(p);
  StyleProblem sp;
  sp.node.create(mask.size());
  sp.node.setTo(-1);
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x)
      if (mask(y, x)) {
        sp.node(y, x) = static_cast<int>(sp.pixels.size());
        sp.pixels.emplace_back(x, y);
      }
  LabelProblem& lp = sp.problem;
  const int n = static_cast<int>(sp.pixels.size());
  lp.nodes = n;
  lp.labels = kStyleCount;
  lp.unary.assign(static_cast<size_t>(n) * kStyleCount, 0.0);  // eq. 4: zero off C
  lp.distance.resize(kStyleCount * kStyleCount);
  for (int a = 0; a < kStyleCount; ++a)
    for (int b = 0; b < kStyleCount; ++b)
      lp.distance[a * kStyleCount + b] = smooth_cost(Style(a), Style(b), p);
  lp.label_cost.assign(p.label_cost, p.label_cost + kStyleCount);

  // C: contour pixels with a valid width, and the zero pixels of the distance transform below.
  cv::Mat1b not_c(mask.size(), uchar(255));
  bool any_c = false;
  for (size_t i = 0; i < widths.contour.size(); ++i) {
    const float w = widths.width[i];
    if (w <= 0) continue;
    const cv::Point q = widths.contour[i];
    const int v = sp.node(q);
    for (int s = 0; s < kStyleCount; ++s)
      lp.unary[static_cast<size_t>(v) * kStyleCount + s] = data_cost(Style(s), w, p);
    not_c(q) = 0;
    any_c = true;
  }
  lp.edges.reserve(static_cast<size_t>(n) * 3);
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x) {
      const int v = sp.node(y, x);
      if (v < 0) continue;
      if (x + 1 < mask.cols && sp.node(y, x + 1) >= 0) lp.edges.push_back({v, sp.node(y, x + 1), 1.0});
      if (y + 1 < mask.rows && sp.node(y + 1, x) >= 0) lp.edges.push_back({v, sp.node(y + 1, x), 1.0});
    }
  if (any_c) {
    // The second kind of neighbour (eq. 5): each pixel's nearest pixel of C. With
    // DIST_LABEL_PIXEL every zero pixel gets its own label, numbered in raster order.
    cv::Mat dist;
    cv::Mat1i nearest;
    cv::distanceTransform(not_c, dist, nearest, cv::DIST_L2, 5, cv::DIST_LABEL_PIXEL);
    std::vector<cv::Point> c_pixels;
    for (int y = 0; y < mask.rows; ++y)
      for (int x = 0; x < mask.cols; ++x)
        if (!not_c(y, x)) c_pixels.emplace_back(x, y);
    for (int v = 0; v < n; ++v) {
      const cv::Point q = sp.pixels[v];
      if (!not_c(q)) continue;
      const int label = nearest(q);
      if (label < 1 || label > static_cast<int>(c_pixels.size())) continue;
      lp.edges.push_back({v, sp.node(c_pixels[label - 1]), 1.0});
    }
  }
  return sp;
}

StyleSolution solve_styles(const LabelProblem& lp) {
  StyleSolution out;
  const int L = lp.labels;
  std::vector<double> single(L, 0.0);
  double bound = 0;
  for (int v = 0; v < lp.nodes; ++v) {
    const double* u = &lp.unary[static_cast<size_t>(v) * L];
    for (int l = 0; l < L; ++l) single[l] += u[l];
    bound += *std::min_element(u, u + L);
  }
  if (lp.nodes > 0) bound += *std::min_element(lp.label_cost.begin(), lp.label_cost.end());
  int best = 0;
  for (int l = 0; l < L; ++l) {
    single[l] += lp.nodes > 0 ? lp.label_cost[l] : 0.0;
    if (single[l] < single[best]) best = l;
  }
  out.single = Style(best);
  out.single_energy = single[best];
  out.labels.assign(lp.nodes, best);
  out.energy = single[best];
  if (out.energy <= bound + 1e-9 * std::max(1.0, std::abs(bound))) return out;  // optimal
  Expansion e = expand(lp, out.labels);
  out.labels = std::move(e.labels);
  out.energy = e.energy;
  out.graph_cut = true;
  return out;
}

StyleSolution solve_styles(const StyleProblem& sp, int max_cut_nodes) {
  const int n = sp.problem.nodes;
  if (n <= max_cut_nodes) return solve_styles(sp.problem);
  const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n) / max_cut_nodes)));
  const int bw = (sp.node.cols + side - 1) / side, bh = (sp.node.rows + side - 1) / side;
  std::vector<int> block_group(static_cast<size_t>(bw) * bh, -1), group(n);
  int groups = 0;
  for (int v = 0; v < n; ++v) {
    const cv::Point q = sp.pixels[v];
    int& g = block_group[static_cast<size_t>(q.y / side) * bw + q.x / side];
    if (g < 0) g = groups++;
    group[v] = g;
  }
  StyleSolution coarse = solve_styles(coarsen(sp.problem, group, groups));
  StyleSolution out = coarse;
  out.labels.resize(n);
  for (int v = 0; v < n; ++v) out.labels[v] = coarse.labels[group[v]];
  out.energy = labelling_energy(sp.problem, out.labels);
  return out;
}

cv::Mat1b label_component(const cv::Mat1b& mask, cv::Point origin, cv::Size image,
                          const LabelParams& p, int min_area_px, bool* forced) {
  validate_label_params(p);
  cv::Mat1b style(mask.size(), uchar(255));
  const int area = cv::countNonZero(mask);
  const StrokeWidths widths = stroke_widths(mask, origin, image);
  const bool force = swt_forces_long_short(widths.failures, area);
  if (forced) *forced = force;
  if (force) {
    style.setTo(static_cast<uchar>(Style::long_short), mask);
    return style;
  }
  // The cheap test of solve_styles first, on C alone (data costs are zero elsewhere): when the
  // best single label meets the lower bound, the problem's graph is never built.
  {
    double single[kStyleCount] = {0, 0, 0}, bound = 0;
    for (float w : widths.width) {
      if (w <= 0) continue;
      double lo = std::numeric_limits<double>::infinity();
      for (int s = 0; s < kStyleCount; ++s) {
        const double d = data_cost(Style(s), w, p);
        single[s] += d;
        lo = std::min(lo, d);
      }
      bound += lo;
    }
    bound += *std::min_element(p.label_cost, p.label_cost + kStyleCount);
    int best = 0;
    for (int s = 0; s < kStyleCount; ++s) {
      single[s] += p.label_cost[s];
      if (single[s] < single[best]) best = s;
    }
    if (single[best] <= bound + 1e-9 * std::max(1.0, std::abs(bound))) {
      style.setTo(static_cast<uchar>(best), mask);
      return style;
    }
  }
  bool graph_cut = false;
  if (area <= p.max_cut_nodes) {
    const StyleProblem sp = style_problem(mask, widths, p);
    const StyleSolution sol = solve_styles(sp.problem);
    for (size_t v = 0; v < sp.pixels.size(); ++v) style(sp.pixels[v]) = static_cast<uchar>(sol.labels[v]);
    graph_cut = sol.graph_cut;
  } else {
    // The same blocks as solve_styles(sp, max_cut_nodes), the problem built on them directly.
    const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(area) / p.max_cut_nodes)));
    std::vector<int> group_of_block;
    int bw = 0;
    const LabelProblem coarse = block_problem(mask, widths, p, side, group_of_block, bw);
    const StyleSolution sol = solve_styles(coarse);
    for (int y = 0; y < mask.rows; ++y) {
      const uchar* m = mask[y];
      uchar* s = style[y];
      const int* row = &group_of_block[static_cast<size_t>(y / side) * bw];
      for (int x = 0; x < mask.cols; ++x)
        if (m[x]) s[x] = static_cast<uchar>(sol.labels[row[x / side]]);
    }
    graph_cut = sol.graph_cut;
  }
  if (graph_cut) absorb_islands(style, mask, min_area_px);
  return style;
}

}  // namespace atelier::embroidery
