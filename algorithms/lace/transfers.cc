#include "algorithms/lace/transfers.h"

#include <algorithm>
#include <cstdlib>
#include <set>
#include <stdexcept>

namespace atelier::lace {

RowTransfers row_transfers(const Row& row) {
  RowTransfers t;
  t.produced = produced(row);
  t.consumed = consumed(row);
  t.target.reserve(static_cast<size_t>(t.consumed));
  t.layer.reserve(static_cast<size_t>(t.consumed));
  t.stack.resize(row.size());
  int s = 0;
  for (int o = 0; o < static_cast<int>(row.size()); ++o) {
    // Layers of the symbol's stitches in knitting order (see the header).
    std::vector<int> layers;
    switch (row[static_cast<size_t>(o)]) {
      case Symbol::yo: break;
      case Symbol::k: layers = {0}; break;
      case Symbol::k2tog: layers = {0, 1}; break;
      case Symbol::ssk: layers = {1, 0}; break;
      case Symbol::sk2p: layers = {2, 0, 1}; break;  // s on top: leans left
      case Symbol::s2kp: layers = {1, 2, 0}; break;  // s+2 bottom, s, the centre s+1 on top
    }
    auto& stack = t.stack[static_cast<size_t>(o)];
    stack.assign(layers.size(), 0);
    for (size_t i = 0; i < layers.size(); ++i, ++s) {
      t.target.push_back(o);
      t.layer.push_back(layers[i]);
      stack[static_cast<size_t>(layers[i])] = s;
    }
  }
  return t;
}

Row tile_row(const Row& row, int times) {
  if (times < 1) throw std::invalid_argument("lace: a row is repeated at least once");
  Row out;
  out.reserve(row.size() * static_cast<size_t>(times));
  for (int i = 0; i < times; ++i) out.insert(out.end(), row.begin(), row.end());
  return out;
}

std::string rs_row_name(int r) { return "row " + std::to_string(2 * r + 1) + " (RS)"; }

namespace {

// Stitch o of a tiled row as the knitter names it in the chart row: "stitch 3 (k2tog)".
std::string stitch_name(const Row& row, int o) {
  const int w = static_cast<int>(row.size());
  const int i = o % w;
  return "stitch " + std::to_string(i + 1) + " (" + std::string(name(row[static_cast<size_t>(i)])) + ")";
}

// Whether the decrease at needle o can be stacked by single-needle moves that arrive on top:
// a stitch already on needle o must be the bottom one, stitches from one side arrive nearest
// first, so their layers must grow with the distance.
bool stack_reachable(const std::vector<int>& stack, int o) {
  int last_left = o, last_right = o;  // nearest position that has arrived from each side
  for (size_t layer = 0; layer < stack.size(); ++layer) {
    const int s = stack[layer];
    if (s == o) {
      if (layer != 0) return false;
    } else if (s < o) {
      if (s >= last_left) return false;
      last_left = s;
    } else {
      if (s <= last_right) return false;
      last_right = s;
    }
  }
  return true;
}

// Greedy schedule: each pass moves every stitch that may move in the pass's direction. Stitches
// moving the same way are never adjacent (one could not move onto the other), so the selection
// is always legal. Returns false when a row stalls (only for rows the static checks missed).
bool simulate(const RowTransfers& t, std::vector<LacePass>& passes) {
  const int w = t.consumed;
  std::vector<int> pos(static_cast<size_t>(w));
  std::vector<std::vector<int>> bed(static_cast<size_t>(w));
  for (int s = 0; s < w; ++s) {
    pos[static_cast<size_t>(s)] = s;
    bed[static_cast<size_t>(s)].push_back(s);
  }
  auto done = [&](int s) { return pos[static_cast<size_t>(s)] == t.target[static_cast<size_t>(s)]; };
  auto all_done = [&] {
    for (int s = 0; s < w; ++s)
      if (!done(s)) return false;
    return true;
  };
  auto settled = [&](int q) {  // every loop on needle q is at home
    for (int s : bed[static_cast<size_t>(q)])
      if (!done(s)) return false;
    return true;
  };
  auto movable = [&](int s, int dir) {
    const int p = pos[static_cast<size_t>(s)], goal = t.target[static_cast<size_t>(s)];
    if (p == goal || (goal > p ? 1 : -1) != dir) return false;
    const int q = p + dir;
    if (q < 0 || q >= w) return false;
    const auto& there = bed[static_cast<size_t>(q)];
    if (q != goal) return there.empty();
    return settled(q) && static_cast<int>(there.size()) == t.layer[static_cast<size_t>(s)];
  };

  int dir = 1;  // parked left: the first pass goes left -> right
  int idle = 0;
  while (!all_done()) {
    LacePass pass;
    pass.direction = dir > 0 ? LaceDirection::left_to_right : LaceDirection::right_to_left;
    std::vector<int> moving;
    for (int s = 0; s < w; ++s) {
      if (!movable(s, dir)) continue;
      const int p = pos[static_cast<size_t>(s)];
      if (!pass.needles.empty() && p - pass.needles.back() < 2) continue;  // never adjacent
      pass.needles.push_back(p);
      moving.push_back(s);
    }
    for (int s : moving) {
      const int p = pos[static_cast<size_t>(s)];
      auto& from = bed[static_cast<size_t>(p)];
      from.erase(std::find(from.begin(), from.end(), s));
      pos[static_cast<size_t>(s)] = p + dir;
      bed[static_cast<size_t>(p + dir)].push_back(s);
    }
    idle = moving.empty() ? idle + 1 : 0;
    passes.push_back(std::move(pass));
    if (idle >= 2) return false;
    dir = -dir;
  }
  if (passes.size() % 2 != 0) passes.push_back(LacePass{LaceDirection::right_to_left, {}});
  return true;
}

}  // namespace

LaceRowSchedule schedule_lace_row(const Row& row, int repeats, int chart_row, const CarriageLimits& limits) {
  LaceRowSchedule out;
  const std::string where = rs_row_name(chart_row);
  if (row.empty()) {
    out.problems.push_back(where + " has no stitches");
    return out;
  }
  if (consumed(row) != produced(row)) {
    out.problems.push_back(where + " makes " + std::to_string(produced(row)) + " stitches from " +
                           std::to_string(consumed(row)) +
                           ": the lace carriage cannot change the width (needles are not added or taken "
                           "away), so every row needs as many yarn-overs as its decreases take away");
    return out;
  }
  const Row tiled = tile_row(row, repeats);
  const RowTransfers t = row_transfers(tiled);

  std::set<int> reported;  // chart stitches already named (repeats share them)
  for (int o = 0; o < t.produced; ++o) {
    const auto& stack = t.stack[static_cast<size_t>(o)];
    if (stack.size() < 2 || stack_reachable(stack, o)) continue;
    if (!reported.insert(o % static_cast<int>(row.size())).second) continue;
    out.problems.push_back(
        where + ", " + stitch_name(row, o) +
        ": its stitches would have to arrive in the wrong order -- the lace carriage always lays the "
        "moved stitch on top, so this decrease would come out slanting the other way (a yarn-over "
        "before a k2tog, or after an ssk, is the usual cause); work this row by hand or mirror the "
        "decrease");
  }
  if (!out.problems.empty()) return out;

  if (!simulate(t, out.passes)) {
    out.passes.clear();
    out.problems.push_back(where + ": the lace carriage cannot order these transfers (stitches would have "
                                   "to pass each other)");
    return out;
  }
  const int passes = static_cast<int>(out.passes.size());
  if (passes > limits.max_passes_per_row) {
    // The longest run of stitches shifted the same way: what makes the row slow.
    int best_from = 0, best_len = 0;
    for (int s = 0; s < t.consumed;) {
      const int d = t.target[static_cast<size_t>(s)] - s;
      int e = s + 1;
      if (d != 0) {
        while (e < t.consumed) {
          const int de = t.target[static_cast<size_t>(e)] - e;
          if (de == 0 || (de > 0) != (d > 0)) break;
          ++e;
        }
        if (e - s > best_len) best_len = e - s, best_from = s;
      }
      s = e;
    }
    const int w = static_cast<int>(row.size());
    const int first = t.target[static_cast<size_t>(best_from)] % w + 1;
    const int last = t.target[static_cast<size_t>(best_from + best_len - 1)] % w + 1;
    out.problems.push_back(where + " needs " + std::to_string(passes) +
                           " lace-carriage passes, more than the " + std::to_string(limits.max_passes_per_row) +
                           " allowed per row: " + std::to_string(best_len) + " stitches (stitches " +
                           std::to_string(std::min(first, last)) + " to " + std::to_string(std::max(first, last)) +
                           ") lie between a yarn-over and its decrease and each must be shifted one needle "
                           "per pass; move the yarn-over nearer to its decrease");
    out.passes.clear();
  }
  return out;
}

VbedRowSchedule schedule_vbed_row(const RowTransfers& t, int max_rack) {
  VbedRowSchedule out;
  std::vector<int> moving;
  std::vector<int> home(static_cast<size_t>(t.produced), 0);  // loops in place on each target
  // Per consumed stitch: the racking of its front-to-back (r1) and back-to-front (r2) transfer;
  // r2 - r1 = its offset. Up to max_rack needles: r1 = 0; further (up to 2 x max_rack) it
  // shifts on the way to the back too.
  std::vector<int> r1(static_cast<size_t>(t.consumed), 0), r2(static_cast<size_t>(t.consumed), 0);
  std::set<int> back_used;  // back needles, as -s - r1 (needle numbers relative to the right edge)
  std::vector<int> far;  // stitches moving more than max_rack needles: placed after the near ones
  for (int s = 0; s < t.consumed; ++s) {
    const int o = t.target[static_cast<size_t>(s)];
    if (o == s && t.layer[static_cast<size_t>(s)] == 0) {
      ++home[static_cast<size_t>(o)];  // stays at the bottom of its own stack
      continue;
    }
    moving.push_back(s);
    const int d = s - o;
    if (std::abs(d) > 2 * max_rack) out.ok = false;
    if (std::abs(d) > max_rack) {
      far.push_back(s);
      continue;
    }
    r2[static_cast<size_t>(s)] = d;
    back_used.insert(-s);  // distinct: one stitch per front needle
  }
  // A far stitch takes the first free back needle among the rackings that reach (|r1|, |r2| <=
  // max_rack, r2 - r1 = d), largest r2 first. Bounded: <= 2 x max_rack + 1 tries each.
  for (int s : far) {
    if (!out.ok) break;
    const int d = s - t.target[static_cast<size_t>(s)];
    const int sign = d > 0 ? 1 : -1;
    bool placed = false;
    for (int a = max_rack; a >= std::abs(d) - max_rack && !placed; --a) {
      const int rr2 = sign * a, rr1 = rr2 - d;
      if (std::abs(rr1) > max_rack || back_used.count(-s - rr1)) continue;
      back_used.insert(-s - rr1);
      r1[static_cast<size_t>(s)] = rr1;
      r2[static_cast<size_t>(s)] = rr2;
      placed = true;
    }
    if (!placed) out.ok = false;  // every reachable back needle is taken
  }
  if (moving.empty() || !out.ok) return out;
  {
    std::set<int> racks;
    for (int s : moving) racks.insert(r1[static_cast<size_t>(s)]);
    std::vector<int> order(racks.begin(), racks.end());
    std::stable_sort(order.begin(), order.end(), [](int x, int y) { return std::abs(x) < std::abs(y); });
    for (int r : order) {
      VbedPass pass{true, r, {}};
      for (int s : moving)
        if (r1[static_cast<size_t>(s)] == r) pass.stitches.push_back(s);
      out.passes.push_back(std::move(pass));
    }
  }
  std::vector<int> left = moving;
  int rack = out.passes.back().rack;
  // Layer by layer (a layer-L stitch is ready once the layers below it are home), one pass per
  // offset of that layer, nearest the current racking first; a pass also takes every other
  // ready stitch of its offset. So passes <= 1 + distinct (offset, layer), and each round
  // places the whole lowest remaining layer: at most 3 rounds (sk2p's stack is the tallest).
  auto ready = [&](int s) {
    return home[static_cast<size_t>(t.target[static_cast<size_t>(s)])] == t.layer[static_cast<size_t>(s)];
  };
  while (!left.empty()) {
    int low = t.layer[static_cast<size_t>(left.front())];
    for (int s : left) low = std::min(low, t.layer[static_cast<size_t>(s)]);
    std::set<int> offsets;
    for (int s : left)
      if (t.layer[static_cast<size_t>(s)] == low) {
        if (!ready(s)) {  // a stack whose lower layer never arrives (not from row_transfers)
          out.ok = false;
          out.passes.clear();
          return out;
        }
        offsets.insert(r2[static_cast<size_t>(s)]);
      }
    std::vector<int> order(offsets.begin(), offsets.end());
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return std::abs(a - rack) < std::abs(b - rack); });
    for (int d : order) {
      VbedPass pass{false, d, {}};
      std::vector<int> rest;
      for (int s : left) (r2[static_cast<size_t>(s)] == d && ready(s) ? pass.stitches : rest).push_back(s);
      if (pass.stitches.empty()) continue;  // taken by an earlier pass of this round
      for (int s : pass.stitches) ++home[static_cast<size_t>(t.target[static_cast<size_t>(s)])];
      out.passes.push_back(std::move(pass));
      left = std::move(rest);
      rack = d;
    }
  }
  return out;
}

}  // namespace atelier::lace
