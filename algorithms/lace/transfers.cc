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

namespace {

// Appends a pass, merged into the last one when it has the same racking and direction (one
// carriage pass: at one racking each back needle faces one front needle, so the merged
// transfers never meet).
void push_pass(VbedRowSchedule& out, VbedPass pass) {
  if (pass.stitches.empty()) return;
  if (!out.passes.empty() && out.passes.back().to_back == pass.to_back && out.passes.back().rack == pass.rack) {
    auto& st = out.passes.back().stitches;
    st.insert(st.end(), pass.stitches.begin(), pass.stitches.end());
    return;
  }
  out.passes.push_back(std::move(pass));
}

int sign_of(int x) { return x > 0 ? 1 : x < 0 ? -1 : 0; }

// One schedule of the row. Positions p are needles right - p; the bed offers p in
// [-max_rack, width - 1 + max_rack]. uniform: every stitch that can (it then reaches its
// target from the back, or it moves further and this racking brings it nearer) goes to the
// back at rack `first`; the others as in schedule_vbed_row's comment.
VbedRowSchedule plan_vbed_row(const RowTransfers& t, int max_rack, bool uniform, int first, bool home_first) {
  VbedRowSchedule out;
  const auto at = [](const std::vector<int>& v, int i) -> int { return v[static_cast<size_t>(i)]; };
  const int width = std::max(t.consumed, t.produced);
  const int lo = -max_rack, hi = width - 1 + max_rack;
  std::vector<int> moving;
  std::vector<int> home(static_cast<size_t>(t.produced), 0);  // loops in place on each target
  for (int s = 0; s < t.consumed; ++s) {
    if (at(t.target, s) == s && at(t.layer, s) == 0)
      ++home[static_cast<size_t>(s)];  // stays at the bottom of its own stack
    else
      moving.push_back(s);
  }
  if (moving.empty()) return out;
  std::vector<int> pos(static_cast<size_t>(t.consumed), 0);  // where each moving stitch is now
  std::set<int> front_busy, back_busy;
  for (int s = 0; s < t.consumed; ++s) front_busy.insert(s);
  // Front to back: r1 per stitch. A stitch whose offset d allows it (|d + r1| <= max_rack)
  // can come home from the back in one transfer; a stitch moving further takes the racking
  // that brings it nearest and shuttles below.
  std::vector<int> r1(static_cast<size_t>(t.consumed), 0);
  std::vector<char> placed(static_cast<size_t>(t.consumed), 0);
  auto direct = [&](int s, int r) { return std::abs(s - at(t.target, s) + r) <= max_rack; };
  auto land = [&](int s, int r) {
    r1[static_cast<size_t>(s)] = r;
    pos[static_cast<size_t>(s)] = s + r;
    back_busy.insert(s + r);
    placed[static_cast<size_t>(s)] = 1;
  };
  for (int s : moving) {
    const int d = s - at(t.target, s);
    if (uniform) {
      if (direct(s, first) || (std::abs(d) > 2 * max_rack && -sign_of(d) * first > 0)) land(s, first);
    } else if (std::abs(d) <= max_rack) {
      land(s, 0);  // distinct back needles: one stitch per front needle
    }
  }
  for (int s : moving) {
    if (placed[static_cast<size_t>(s)]) continue;
    const int d = s - at(t.target, s);
    std::vector<int> cand;  // tried in order; bounded: 2 x max_rack + 1
    for (int r = -max_rack; r <= max_rack; ++r)
      if (direct(s, r) || std::abs(d) > 2 * max_rack) cand.push_back(r);
    if (std::abs(d) > 2 * max_rack)
      std::stable_sort(cand.begin(), cand.end(), [&](int a, int b) { return -sign_of(d) * a > -sign_of(d) * b; });
    else
      std::stable_sort(cand.begin(), cand.end(), [](int a, int b) { return std::abs(a) < std::abs(b); });
    for (int r : cand)
      if (!back_busy.count(s + r)) {
        land(s, r);
        break;
      }
    if (!placed[static_cast<size_t>(s)]) {  // every back needle it could reach is taken
      out.ok = false;
      return out;
    }
  }
  for (int s = 0; s < t.consumed; ++s)
    if (placed[static_cast<size_t>(s)]) front_busy.erase(s);
  {
    std::set<int> racks;
    for (int s : moving) racks.insert(at(r1, s));
    std::vector<int> order(racks.begin(), racks.end());
    std::stable_sort(order.begin(), order.end(), [](int x, int y) { return std::abs(x) < std::abs(y); });
    for (int r : order) {
      VbedPass pass{true, r, {}};
      for (int s : moving)
        if (at(r1, s) == r) pass.stitches.push_back(s);
      push_pass(out, std::move(pass));
    }
  }
  // Shuttle: a stitch still more than max_rack needles from its target goes to a free front
  // needle up to max_rack nearer and back to a free back needle up to max_rack nearer again;
  // one pass per racking and direction, largest shifts first, so a row's far stitches shift
  // together. Returns false when no far stitch gets nearer (the caller gives up).
  auto gap = [&](int s) { return at(pos, s) - at(t.target, s); };  // > 0: heads to lower positions
  std::vector<char> is_home(static_cast<size_t>(t.consumed), 0);
  auto far_total = [&] {
    int sum = 0;
    for (int s : moving)
      if (!is_home[static_cast<size_t>(s)] && std::abs(gap(s)) > max_rack) sum += std::abs(gap(s));
    return sum;
  };
  auto shuttle = [&]() -> bool {
    const int total = far_total();
    std::vector<int> up;  // on the front this round
    std::vector<int> heading(static_cast<size_t>(t.consumed), 0);
    for (int a = max_rack; a >= 1; --a)
      for (int sg : {1, -1}) {
        VbedPass pass{false, sg * a, {}};  // b(q) -> f(q - rack) in positions
        for (int s : moving) {
          if (is_home[static_cast<size_t>(s)] || std::abs(gap(s)) <= max_rack || sign_of(gap(s)) != sg ||
              heading[static_cast<size_t>(s)])
            continue;
          const int p = at(pos, s) - sg * a;
          if (p < lo || p > hi || front_busy.count(p)) continue;
          back_busy.erase(at(pos, s));
          front_busy.insert(p);
          pos[static_cast<size_t>(s)] = p;
          heading[static_cast<size_t>(s)] = sg;
          pass.stitches.push_back(s);
          up.push_back(s);
        }
        push_pass(out, std::move(pass));
      }
    if (up.empty()) return false;  // no far stitch finds a free front needle
    std::vector<char> down(static_cast<size_t>(t.consumed), 0);
    for (int a = max_rack; a >= -max_rack; --a)
      for (int sg : {1, -1}) {
        VbedPass pass{true, -sg * a, {}};  // f(p) -> b(p + rack) in positions
        for (int s : up) {
          if (down[static_cast<size_t>(s)] || heading[static_cast<size_t>(s)] != sg) continue;
          const int q = at(pos, s) - sg * a;
          if (q < lo || q > hi || back_busy.count(q)) continue;
          front_busy.erase(at(pos, s));
          back_busy.insert(q);
          pos[static_cast<size_t>(s)] = q;
          down[static_cast<size_t>(s)] = 1;
          pass.stitches.push_back(s);
        }
        push_pass(out, std::move(pass));
      }
    for (int s : up)
      if (!down[static_cast<size_t>(s)]) return false;  // no free back needle within reach
    return far_total() < total;
  };
  // Back to front: rounds of the ready stitches (lower layers home) within max_rack of their
  // target, lowest layer first; one pass per racking r2 = pos - target, nearest the current
  // racking first; a pass also takes every other ready stitch of its racking. Returns how
  // many came home. Without far stitches each round places the whole lowest remaining layer:
  // at most 3 rounds (sk2p's stack is the tallest).
  int rack = out.passes.back().rack;
  auto ready = [&](int s) {
    return !is_home[static_cast<size_t>(s)] && std::abs(gap(s)) <= max_rack &&
           at(home, at(t.target, s)) == at(t.layer, s);
  };
  auto go_home = [&]() -> int {
    int placed_home = 0;
    for (int round = 0; round <= 3; ++round) {  // 3 layers at most: bounded
      int low = -1;
      for (int s : moving)
        if (ready(s) && (low < 0 || at(t.layer, s) < low)) low = at(t.layer, s);
      if (low < 0) break;
      std::set<int> offsets;
      for (int s : moving)
        if (ready(s) && at(t.layer, s) == low) offsets.insert(gap(s));
      std::vector<int> order(offsets.begin(), offsets.end());
      std::stable_sort(order.begin(), order.end(),
                       [&](int a, int b) { return std::abs(a - rack) < std::abs(b - rack); });
      for (int d : order) {
        VbedPass pass{false, d, {}};
        for (int s : moving)
          if (gap(s) == d && ready(s)) pass.stitches.push_back(s);
        if (pass.stitches.empty()) continue;  // taken by an earlier pass of this round
        for (int s : pass.stitches) {
          ++home[static_cast<size_t>(at(t.target, s))];
          is_home[static_cast<size_t>(s)] = 1;
          back_busy.erase(at(pos, s));
          front_busy.insert(at(t.target, s));
          ++placed_home;
        }
        push_pass(out, std::move(pass));
        rack = d;
      }
    }
    return placed_home;
  };
  // home_first: the stitches already near go home before the far ones shuttle (their back
  // needles are then free to shuttle through); else every far stitch shuttles first.
  // Bounded: each step homes a stitch or brings the far ones nearer in total.
  int left = static_cast<int>(moving.size());
  const int max_steps = left + far_total() + 1;
  for (int step = 0; left > 0; ++step) {
    if (step > max_steps) {  // cannot happen while each step progresses; a guard
      out.ok = false;
      return out;
    }
    const bool any_far = far_total() > 0;
    if (any_far && !home_first) {
      if (!shuttle()) {
        out.ok = false;
        return out;
      }
      continue;
    }
    const int placed_home = go_home();
    left -= placed_home;
    if (left == 0) break;
    if (any_far ? !shuttle() : placed_home == 0) {  // stuck, or a stacking order never met
      out.ok = false;
      out.passes.clear();
      return out;
    }
  }
  return out;
}

}  // namespace

VbedRowSchedule schedule_vbed_row(const RowTransfers& t, int max_rack) {
  // A few ways to pick the first racking and the order of near and far stitches; the one with
  // the fewest passes wins (the first on a tie: near stitches at rack 0, far ones shuttled
  // first). Bounded: 2 x (2 x max_rack + 1) plans.
  VbedRowSchedule best;
  best.ok = false;
  for (bool home_first : {false, true})
    for (int first = 0; first <= 2 * max_rack; ++first) {
      const int r = first == 0 ? 0 : first <= max_rack ? -first : first - max_rack;  // 0, -1.., 1..
      VbedRowSchedule p = plan_vbed_row(t, max_rack, r != 0, r, home_first);
      if (p.ok && (!best.ok || p.passes.size() < best.passes.size())) best = std::move(p);
    }
  return best;
}

}  // namespace atelier::lace
