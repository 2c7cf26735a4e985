// Alpha-expansion with label costs (algorithms/embroidery/alpha_expansion.h): local optimum,
// label costs, metric check, coarsening.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "algorithms/embroidery/alpha_expansion.h"

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

}  // namespace
}  // namespace atelier::embroidery
