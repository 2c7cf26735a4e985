// The stitch-style energy of paper section 4 (algorithms/embroidery/style_labels.h): data and
// smoothness costs, and the graph cut against the best single style.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>

#include "algorithms/embroidery/alpha_expansion.h"
#include "algorithms/embroidery/colors.h"
#include "algorithms/embroidery/style_labels.h"
#include "algorithms/embroidery/swt.h"

namespace atelier::embroidery {
namespace {

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
