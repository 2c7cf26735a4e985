#include "algorithms/embroidery/alpha_expansion.h"

#include <boost/graph/boykov_kolmogorov_max_flow.hpp>
#include <boost/graph/compressed_sparse_row_graph.hpp>
#include <boost/property_map/property_map.hpp>

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace atelier::embroidery {
namespace {

// A compressed sparse row graph keeps every edge in one array (adjacency_list would allocate
// each edge's properties on the heap); capacities live in vectors indexed by edge index.
using Graph = boost::compressed_sparse_row_graph<boost::directedS>;
using Vertex = boost::graph_traits<Graph>::vertex_descriptor;
using EdgeDesc = boost::graph_traits<Graph>::edge_descriptor;

// Costs are quantised to 1/kScale for the max-flow (see min_cut); the caller compares moves
// on the exact energy.
constexpr double kScale = 1 << 20;

// One directed arc u -> v with capacity `cap`; its reverse arc (capacity 0) is added with it.
struct Arc {
  int u, v;
  double cap;
};

// Solves the cut of the binary energy  sum_v (x_v ? cost1 : cost0) + sum_arcs cap*[x_u=0, x_v=1]
// and returns x (1 = sink side). Source side = 0 (keep), sink side = 1.
std::vector<char> min_cut(int n, const std::vector<double>& cost0, const std::vector<double>& cost1,
                          const std::vector<Arc>& arcs) {
  const int s = n, t = n + 1, nv = n + 2;
  // Every arc and t-link becomes a pair (arc, reverse). Count out-degrees, then place the
  // arcs in source order so the CSR edge index of each is known (and so its reverse).
  std::vector<int> degree(nv + 1, 0);
  auto count = [&](int u, int v) { ++degree[u]; ++degree[v]; };
  for (const Arc& a : arcs) count(a.u, a.v);
  for (int v = 0; v < n; ++v)
    if (cost1[v] != cost0[v]) count(cost1[v] > cost0[v] ? s : v, cost1[v] > cost0[v] ? v : t);
  std::vector<int> start(nv + 1, 0);
  for (int v = 0; v < nv; ++v) start[v + 1] = start[v] + degree[v];
  const size_t m = static_cast<size_t>(start[nv]);
  std::vector<std::pair<Vertex, Vertex>> ends(m);
  std::vector<long long> cap(m, 0);
  // Integer capacities: with doubles, rounding leaves tiny residuals on augmenting paths and
  // BK then crawls through endless near-zero augmentations. Scale so the total stays exact.
  double total = 0;
  for (const Arc& a : arcs) total += std::max(0.0, a.cap);
  for (int v = 0; v < n; ++v) total += std::abs(cost1[v] - cost0[v]);
  const double scale = std::min(kScale, 0x1p52 / std::max(total, 1.0));
  auto quant = [scale](double c) { return static_cast<long long>(std::llround(c * scale)); };
  std::vector<size_t> rev_index(m);
  std::vector<int> fill(start.begin(), start.end() - 1);
  auto place = [&](int u, int v, double c) {
    const size_t e = static_cast<size_t>(fill[u]++), r = static_cast<size_t>(fill[v]++);
    ends[e] = {static_cast<Vertex>(u), static_cast<Vertex>(v)};
    ends[r] = {static_cast<Vertex>(v), static_cast<Vertex>(u)};
    cap[e] = quant(c);
    rev_index[e] = r;
    rev_index[r] = e;
  };
  for (const Arc& a : arcs) place(a.u, a.v, std::max(0.0, a.cap));
  for (int v = 0; v < n; ++v) {
    const double d = cost1[v] - cost0[v];
    if (d > 0) place(s, v, d);       // cut when v is on the sink side: x_v = 1 costs d more
    else if (d < 0) place(v, t, -d); // cut when v is on the source side: x_v = 0 costs -d more
  }
  Graph g(boost::edges_are_sorted, ends.begin(), ends.end(), static_cast<size_t>(nv));
  // Edge index i of the CSR graph is the i-th edge of `ends` (they were given sorted).
  std::vector<EdgeDesc> rev(m);
  for (size_t e = 0; e < m; ++e) rev[e] = EdgeDesc(ends[rev_index[e]].first, rev_index[e]);
  std::vector<long long> residual(m, 0);
  std::vector<EdgeDesc> pred(nv);
  std::vector<boost::default_color_type> color(nv);
  std::vector<long> dist(nv, 0);
  const auto eidx = get(boost::edge_index, g);
  const auto vidx = get(boost::vertex_index, g);
  boost::boykov_kolmogorov_max_flow(
      g, boost::make_iterator_property_map(cap.begin(), eidx),
      boost::make_iterator_property_map(residual.begin(), eidx),
      boost::make_iterator_property_map(rev.begin(), eidx),
      boost::make_iterator_property_map(pred.begin(), vidx),
      boost::make_iterator_property_map(color.begin(), vidx),
      boost::make_iterator_property_map(dist.begin(), vidx), vidx, static_cast<Vertex>(s),
      static_cast<Vertex>(t));
  std::vector<char> x(n);
  // Black = the source tree (reachable from s in the residual graph) = label 0.
  for (int v = 0; v < n; ++v) x[v] = color[v] == boost::black_color ? 0 : 1;
  return x;
}

}  // namespace

void validate_problem(const LabelProblem& p) {
  auto fail = [](const std::string& what) {
    throw std::invalid_argument("label problem: " + what);
  };
  if (p.nodes < 0 || p.labels < 1 || p.labels > 12) fail("needs nodes >= 0 and 1..12 labels");
  const size_t L = static_cast<size_t>(p.labels);
  if (p.unary.size() != static_cast<size_t>(p.nodes) * L) fail("unary must have nodes*labels entries");
  if (p.distance.size() != L * L) fail("distance must have labels*labels entries");
  if (p.label_cost.size() != L) fail("label_cost must have labels entries");
  for (double u : p.unary)
    if (!std::isfinite(u)) fail("unary cost not finite");
  for (double c : p.label_cost)
    if (!std::isfinite(c) || c < 0) fail("label cost negative or not finite");
  for (const LabelProblem::Edge& e : p.edges)
    if (e.a < 0 || e.b < 0 || e.a >= p.nodes || e.b >= p.nodes || e.a == e.b ||
        !std::isfinite(e.weight) || e.weight < 0)
      fail("edge with a bad node or a negative weight");
  auto V = [&](size_t a, size_t b) { return p.distance[a * L + b]; };
  for (size_t a = 0; a < L; ++a)
    for (size_t b = 0; b < L; ++b) {
      if (!std::isfinite(V(a, b)) || V(a, b) < 0) fail("distance negative or not finite");
      if (a == b && V(a, b) != 0) fail("distance of a label to itself must be 0");
      if (V(a, b) != V(b, a)) fail("distance must be symmetric");
      for (size_t c = 0; c < L; ++c)
        if (V(a, c) > V(a, b) + V(b, c) + 1e-12 * (1 + V(a, c)))
          fail("distance breaks the triangle inequality (expansion needs a metric)");
    }
}

double labelling_energy(const LabelProblem& p, const std::vector<int>& f) {
  if (f.size() != static_cast<size_t>(p.nodes))
    throw std::invalid_argument("label problem: labelling has the wrong size");
  const int L = p.labels;
  double e = 0;
  std::vector<char> used(L, 0);
  for (int n = 0; n < p.nodes; ++n) {
    if (f[n] < 0 || f[n] >= L) throw std::invalid_argument("label problem: label out of range");
    e += p.unary[static_cast<size_t>(n) * L + f[n]];
    used[f[n]] = 1;
  }
  for (const LabelProblem::Edge& ed : p.edges) e += ed.weight * p.distance[f[ed.a] * L + f[ed.b]];
  for (int l = 0; l < L; ++l)
    if (used[l]) e += p.label_cost[l];
  return e;
}

namespace {

// The best alpha-expansion of f in which every node labelled alpha or with a label in
// `vanish` takes alpha, all other nodes choosing freely; label costs are left out of the cut
// (within one such branch they are constants) and counted by the caller on the true energy.
std::vector<int> best_move(const LabelProblem& p, const std::vector<int>& f, int alpha,
                           const std::vector<char>& vanish, std::vector<int>& var, int& cuts) {
  const int L = p.labels;
  int n = 0;
  for (int v = 0; v < p.nodes; ++v) var[v] = f[v] == alpha || vanish[f[v]] ? -1 : n++;
  std::vector<int> g = f;
  for (int v = 0; v < p.nodes; ++v)
    if (var[v] < 0) g[v] = alpha;
  if (n == 0) return g;
  std::vector<double> cost0(n, 0.0), cost1(n, 0.0);
  std::vector<Arc> arcs;
  arcs.reserve(p.edges.size());
  for (int v = 0; v < p.nodes; ++v) {
    if (var[v] < 0) continue;
    cost0[var[v]] += p.unary[static_cast<size_t>(v) * L + f[v]];
    cost1[var[v]] += p.unary[static_cast<size_t>(v) * L + alpha];
  }
  for (const LabelProblem::Edge& e : p.edges) {
    const int a = var[e.a], b = var[e.b];
    if (a < 0 && b < 0) continue;
    if (a < 0 || b < 0) {  // one end is alpha after the move: a unary term on the other
      const int v = a < 0 ? e.b : e.a;
      cost0[var[v]] += e.weight * p.distance[f[v] * L + alpha];
      continue;
    }
    // E(x_a, x_b): A = E(0,0), B = E(0,1), C = E(1,0), D = E(1,1) = 0.
    // E = A + (C-A) x_a + (D-C) x_b + (B+C-A-D) [x_a = 0, x_b = 1]; B+C-A-D >= 0 by the
    // triangle inequality, so the move is submodular.
    const double A = e.weight * p.distance[f[e.a] * L + f[e.b]];
    const double B = e.weight * p.distance[f[e.a] * L + alpha];
    const double C = e.weight * p.distance[alpha * L + f[e.b]];
    cost1[a] += C - A;
    cost1[b] -= C;
    const double pair = B + C - A;
    if (pair > 0) arcs.push_back({a, b, pair});
  }
  const std::vector<char> x = min_cut(n, cost0, cost1, arcs);
  ++cuts;
  for (int v = 0; v < p.nodes; ++v)
    if (var[v] >= 0 && x[var[v]]) g[v] = alpha;
  return g;
}

}  // namespace

Expansion expand(const LabelProblem& p, std::vector<int> f) {
  validate_problem(p);
  const int L = p.labels;
  Expansion out;
  out.energy = labelling_energy(p, f);  // also checks f
  std::vector<int> var(p.nodes);
  int unchanged = 0;  // consecutive alphas without an accepted move
  int last = -1;      // the alpha of the last accepted move
  for (int alpha = 0; unchanged < L; alpha = (alpha + 1) % L) {
    ++unchanged;
    // Back at the last accepted alpha with nothing changed since: f is that move's optimum, and
    // every alpha-expansion of f is also one of the labelling it came from, so none is better.
    if (alpha == last) continue;
    // Label costs (Delong et al. 2012) make the move's energy higher-order: label l != alpha
    // costs c_l unless all its nodes take alpha. The exact move is the best over which of the
    // used, costed labels vanish: for each choice, those labels' nodes are fixed to alpha and
    // the others cost c_l as a constant, leaving a pairwise submodular energy for one cut.
    // (Delong's auxiliary node per label would do it in one cut, but it links to every node
    // of its label, and Boykov-Kolmogorov's orphan adoption on such a hub went quadratic on
    // pixel grids: 31 s instead of 0.1 s on a 50k-pixel component.)
    std::vector<char> used(L, 0);
    for (int v = 0; v < p.nodes; ++v) used[f[v]] = 1;
    std::vector<int> costed;
    for (int l = 0; l < L; ++l)
      if (l != alpha && used[l] && p.label_cost[l] > 0) costed.push_back(l);
    double best_e = out.energy;
    std::vector<int> best;
    for (unsigned choice = 0; choice < (1u << costed.size()); ++choice) {
      std::vector<char> vanish(L, 0);
      for (size_t i = 0; i < costed.size(); ++i) vanish[costed[i]] = (choice >> i) & 1u;
      std::vector<int> g = best_move(p, f, alpha, vanish, var, out.cuts);
      const double e = labelling_energy(p, g);
      if (e < best_e) best_e = e, best = std::move(g);
    }
    if (!best.empty() && best_e < out.energy - 1e-9 * std::max(1.0, std::abs(out.energy))) {
      f = std::move(best);
      out.energy = best_e;
      ++out.moves;
      unchanged = 0;
      last = alpha;
    }
  }
  out.labels = std::move(f);
  return out;
}

}  // namespace atelier::embroidery

namespace atelier::embroidery {

LabelProblem coarsen(const LabelProblem& p, const std::vector<int>& group, int groups) {
  if (group.size() != static_cast<size_t>(p.nodes) || groups < 0)
    throw std::invalid_argument("label problem: coarsen needs one group per node");
  const int L = p.labels;
  LabelProblem c;
  c.nodes = groups;
  c.labels = L;
  c.distance = p.distance;
  c.label_cost = p.label_cost;
  c.unary.assign(static_cast<size_t>(groups) * L, 0.0);
  std::vector<char> seen(groups, 0);
  for (int v = 0; v < p.nodes; ++v) {
    const int g = group[v];
    if (g < 0 || g >= groups) throw std::invalid_argument("label problem: group out of range");
    seen[g] = 1;
    for (int l = 0; l < L; ++l) c.unary[static_cast<size_t>(g) * L + l] += p.unary[static_cast<size_t>(v) * L + l];
  }
  for (char s : seen)
    if (!s) throw std::invalid_argument("label problem: coarsen with an empty group");
  // Sum the weights of edges between the same two groups (distance is symmetric).
  std::vector<std::pair<std::uint64_t, double>> keyed;
  keyed.reserve(p.edges.size());
  for (const LabelProblem::Edge& e : p.edges) {
    const std::uint64_t a = static_cast<std::uint32_t>(group[e.a]), b = static_cast<std::uint32_t>(group[e.b]);
    if (a == b) continue;
    keyed.emplace_back(std::min(a, b) << 32 | std::max(a, b), e.weight);
  }
  std::sort(keyed.begin(), keyed.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  for (size_t i = 0; i < keyed.size();) {
    double w = 0;
    size_t j = i;
    while (j < keyed.size() && keyed[j].first == keyed[i].first) w += keyed[j++].second;
    c.edges.push_back({static_cast<int>(keyed[i].first >> 32), static_cast<int>(keyed[i].first & 0xffffffffu), w});
    i = j;
  }
  return c;
}

}  // namespace atelier::embroidery
