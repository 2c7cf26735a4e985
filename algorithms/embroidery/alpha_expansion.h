// Multi-label energy minimisation by alpha-expansion with label costs (Boykov, Veksler and
// Zabih 2001; label costs as in Delong, Osokin, Isack and Boykov 2012), each move solved by
// s-t minimum cuts with Boost.Graph's boykov_kolmogorov_max_flow. A move with label costs is
// solved exactly as the best of one cut per choice of which costed labels vanish (2^(k) cuts,
// k = labels in use other than alpha with a cost; k <= 2 for the three stitch styles).
// Cut capacities are quantised to 2^-20 of a cost unit; moves are accepted on the exact energy.
//
// Energy of a labelling f (one label per node):
//   E(f) = sum_n unary[n][f_n] + sum_edges weight * distance[f_a][f_b] + sum_{L used} label_cost[L]
// `distance` must be a metric on the labels (zero diagonal, symmetric, triangle inequality):
// that makes every expansion move submodular, so each move is solved exactly.
// Units: whatever the caller's costs are in. Pure; thread-safe (no shared state, each call
// builds its own graphs), so several problems may be solved in parallel.
#pragma once

#include <vector>

namespace atelier::embroidery {

struct LabelProblem {
  struct Edge {
    int a = 0, b = 0;     // node indices, a != b
    double weight = 0;    // >= 0
  };
  int nodes = 0;
  int labels = 0;                  // 1..12
  std::vector<double> unary;       // nodes * labels, unary[n * labels + l]; finite
  std::vector<double> distance;    // labels * labels, a metric (see above)
  std::vector<Edge> edges;
  std::vector<double> label_cost;  // labels entries, >= 0; paid once per label in use
};

// Throws std::invalid_argument (naming the fault) when sizes disagree, a cost is negative or
// not finite, or `distance` is not a metric.
void validate_problem(const LabelProblem& p);

// E(f) as defined above. `labels` has p.nodes entries in [0, p.labels).
double labelling_energy(const LabelProblem& p, const std::vector<int>& labels);

struct Expansion {
  std::vector<int> labels;
  double energy = 0;
  int moves = 0;   // expansion moves accepted
  int cuts = 0;    // max-flow problems solved
};

// Alpha-expansion from `initial` (p.nodes labels): cycles alpha over all labels, accepting a
// move only when it lowers E, until a full cycle changes nothing. The result is a local
// optimum with respect to every expansion move and never has higher energy than `initial`.
// Validates the problem first (see validate_problem).
Expansion expand(const LabelProblem& p, std::vector<int> initial);

}  // namespace atelier::embroidery

namespace atelier::embroidery {

// The problem restricted to labellings constant on each group: node v of `p` belongs to group
// group[v] in [0, groups). Unary costs and label costs carry over, edges inside a group vanish
// and edges between two groups add up. For any labelling g of the groups,
//   labelling_energy(coarse, g) == labelling_energy(p, f) with f[v] = g[group[v]]
// (every group must be non-empty). Used to bound the size of the cuts on large components.
LabelProblem coarsen(const LabelProblem& p, const std::vector<int>& group, int groups);

}  // namespace atelier::embroidery
