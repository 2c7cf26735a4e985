// Alpha-expansion with label costs (alpha_expansion.h) and the stitch-style energy of paper
// section 4 (style_labels.h).
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <random>

#include "algorithms/embroidery/alpha_expansion.h"
#include "algorithms/embroidery/colors.h"
#include "algorithms/embroidery/style_labels.h"
#include "algorithms/embroidery/swt.h"

namespace atelier::embroidery {
namespace {

// A random problem with a random metric (three labels: any positive a, b, c obeying the
// triangle inequality), random edges, unary and label costs.
LabelProblem random_problem(std::mt19937& rng, int nodes, double max_label_cost) {
  std::uniform_real_distribution<double> u(0, 10), w(0, 3), lc(0, max_label_cost);
  LabelProblem p;
  p.nodes = nodes;
  p.labels = 3;
  for (int i = 0; i < nodes * 3; ++i) p.unary.push_back(u(rng));
  double a = 1 + u(rng), b = 1 + u(rng), c = 1 + u(rng);
  const double m = std::max({a, b, c});  // make it a metric: the largest <= sum of the others
  if (m == a) a = std::min(a, b + c);
  if (m == b) b = std::min(b, a + c);
  if (m == c) c = std::min(c, a + b);
  p.distance = {0, a, b, a, 0, c, b, c, 0};
  for (int i = 0; i < nodes; ++i)
    for (int j = i + 1; j < nodes; ++j)
      if (rng() % 2) p.edges.push_back({i, j, w(rng)});
  for (int l = 0; l < 3; ++l) p.label_cost.push_back(lc(rng));
  return p;
}

TEST(EmbroideryAlphaExpansion, ResultIsLocalOptimumOfEveryExpansionMove) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 60; ++trial) {
    const LabelProblem p = random_problem(rng, 6, trial % 2 ? 15.0 : 0.0);
    std::vector<int> init(6);
    for (int& l : init) l = static_cast<int>(rng() % 3);
    const Expansion e = expand(p, init);
    ASSERT_NEAR(e.energy, labelling_energy(p, e.labels), 1e-9);
    EXPECT_LE(e.energy, labelling_energy(p, init) + 1e-9);
    // Brute force: no expansion move (any subset of nodes switching to any alpha) is better.
    for (int alpha = 0; alpha < 3; ++alpha)
      for (int subset = 0; subset < 64; ++subset) {
        std::vector<int> g = e.labels;
        for (int v = 0; v < 6; ++v)
          if (subset >> v & 1) g[v] = alpha;
        ASSERT_GE(labelling_energy(p, g), e.energy - 1e-4)
            << "trial " << trial << " alpha " << alpha << " subset " << subset;
      }
  }
}

TEST(EmbroideryAlphaExpansion, EnergyCountsEachUsedLabelCostOnce) {
  LabelProblem p;
  p.nodes = 3;
  p.labels = 2;
  p.unary = {1, 2, 3, 4, 5, 6};
  p.distance = {0, 10, 10, 0};
  p.edges = {{0, 1, 1.0}, {1, 2, 2.0}};
  p.label_cost = {100, 1000};
  EXPECT_DOUBLE_EQ(labelling_energy(p, {0, 0, 0}), 1 + 3 + 5 + 100);
  EXPECT_DOUBLE_EQ(labelling_energy(p, {0, 1, 0}), 1 + 4 + 5 + 10 * 1 + 10 * 2 + 100 + 1000);
}

TEST(EmbroideryAlphaExpansion, HighLabelCostRemovesTheLabel) {
  // Node 0 prefers label 2 by 5; everyone else prefers label 0.
  LabelProblem p;
  p.nodes = 8;
  p.labels = 3;
  for (int v = 0; v < 8; ++v) {
    if (v == 0) p.unary.insert(p.unary.end(), {5, 8, 0});
    else p.unary.insert(p.unary.end(), {0, 3, 3});
  }
  p.distance = {0, 1, 1, 1, 0, 1, 1, 1, 0};
  for (int v = 0; v + 1 < 8; ++v) p.edges.push_back({v, v + 1, 0.5});
  p.label_cost = {0, 0, 0};
  const Expansion cheap = expand(p, std::vector<int>(8, 0));
  EXPECT_EQ(cheap.labels[0], 2);
  p.label_cost = {0, 0, 50};
  const Expansion dear = expand(p, std::vector<int>(8, 0));
  EXPECT_EQ(std::count(dear.labels.begin(), dear.labels.end(), 2), 0);
  // And a used label with a high cost is removed by a move, not only never introduced.
  std::vector<int> start(8, 2);
  const Expansion removed = expand(p, start);
  EXPECT_EQ(std::count(removed.labels.begin(), removed.labels.end(), 2), 0);
  EXPECT_NEAR(removed.energy, 5 + 0 /* node 0 takes label 0 */, 1e-9);
}

TEST(EmbroideryAlphaExpansion, RejectsDistanceThatIsNotAMetric) {
  LabelProblem p;
  p.nodes = 1;
  p.labels = 3;
  p.unary = {0, 0, 0};
  p.distance = {0, 1, 5, 1, 0, 1, 5, 1, 0};  // 5 > 1 + 1
  p.label_cost = {0, 0, 0};
  EXPECT_THROW(expand(p, {0}), std::invalid_argument);
}

TEST(EmbroideryAlphaExpansion, CoarsenedProblemHasTheSameEnergyAsTheFineOne) {
  std::mt19937 rng(11);
  const LabelProblem p = random_problem(rng, 12, 10);
  std::vector<int> group(12);
  for (int v = 0; v < 12; ++v) group[v] = v / 3;  // four groups of three
  const LabelProblem c = coarsen(p, group, 4);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<int> g(4), f(12);
    for (int& l : g) l = static_cast<int>(rng() % 3);
    for (int v = 0; v < 12; ++v) f[v] = g[group[v]];
    EXPECT_NEAR(labelling_energy(c, g), labelling_energy(p, f), 1e-9);
  }
}

TEST(EmbroideryStyleLabels, DataCostsFavourTheStyleThatFitsTheWidth) {
  const LabelParams p;  // eW 4, sW 24
  auto best = [&](double w) {
    Style s = Style::long_short;
    for (Style t : {Style::satin, Style::edge})
      if (data_cost(t, w, p) < data_cost(s, w, p)) s = t;
    return s;
  };
  EXPECT_EQ(best(2), Style::edge);
  EXPECT_EQ(best(12), Style::satin);
  EXPECT_EQ(best(60), Style::long_short);
  EXPECT_GT(smooth_cost(Style::edge, Style::satin, p), smooth_cost(Style::satin, Style::long_short, p));
  EXPECT_EQ(smooth_cost(Style::satin, Style::satin, p), 0);
}

// Checks solve_styles on one component: energy as stated, never above the best single label.
// Returns whether the graph cut found something strictly better.
bool check_component(const cv::Mat1b& mask, cv::Point origin, cv::Size image, const LabelParams& lp) {
  const StrokeWidths sw = stroke_widths(mask, origin, image);
  const StyleProblem sp = style_problem(mask, sw, lp);
  const StyleSolution sol = solve_styles(sp, lp.max_cut_nodes);
  EXPECT_NEAR(sol.energy, labelling_energy(sp.problem, sol.labels), 1e-6 * (1 + sol.energy));
  double single = 1e300;
  for (int l = 0; l < kStyleCount; ++l)
    single = std::min(single, labelling_energy(sp.problem, std::vector<int>(sp.problem.nodes, l)));
  EXPECT_NEAR(sol.single_energy, single, 1e-6 * (1 + single));
  EXPECT_LE(sol.energy, single + 1e-6 * (1 + single));
  return sol.energy < single - 1e-6 * (1 + single);
}

TEST(EmbroideryStyleLabels, GraphCutNeverDoesWorseThanTheBestSingleLabel) {
  const LabelParams lp;
  int improved = 0, checked = 0;
  // Drawn: a disk with a satin-wide stripe and a thin line growing out of it.
  cv::Mat1b drawn(240, 320, uchar(0));
  cv::circle(drawn, {90, 120}, 60, 255, cv::FILLED);
  cv::rectangle(drawn, cv::Rect(140, 110, 140, 12), 255, cv::FILLED);
  cv::rectangle(drawn, cv::Rect(80, 20, 2, 60), 255, cv::FILLED);
  improved += check_component(drawn, {0, 0}, drawn.size(), lp);
  ++checked;
  // Real: the larger components of fruits.jpg, on full pixels and on blocks.
  const cv::Mat img = cv::imread(std::string(ATELIER_TEST_DATA) + "/fruits.jpg", cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty());
  ColorExtraction ce = extract_colors(img, ColorParams{});
  const Components comp = color_components(ce.color_index, static_cast<int>(ce.palette.bgr.size()), 16);
  for (size_t c = 0; c < comp.color.size(); ++c) {
    if (comp.area_px[c] < 3000) continue;
    const cv::Mat1b mask = comp.id(comp.bbox[c]) == static_cast<int>(c);
    LabelParams fine = lp;
    fine.max_cut_nodes = 1 << 20;
    improved += check_component(mask, comp.bbox[c].tl(), img.size(), checked % 2 ? lp : fine);
    ++checked;
  }
  EXPECT_GE(checked, 5);
  EXPECT_GE(improved, 2);  // the cut really mixes styles somewhere
}

}  // namespace
}  // namespace atelier::embroidery
