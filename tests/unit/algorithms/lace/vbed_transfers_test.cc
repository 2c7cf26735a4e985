// schedule_vbed_row: few transfer passes (grouped by racking), and the loops end
// where row_transfers says, in its stacking order.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "algorithms/lace/transfers.h"
#include "tests/support/lace_test_charts.h"

namespace atelier::lace {
namespace {

using test::row;

constexpr int kMaxRack = 4;

// The bound: one pass to the back per racking r1 (0, or the shift of a stitch moving more
// than 4 needles), then one pass per (r2, layer) of the moving stitches (r2 - r1 = offset).
size_t pass_bound(const RowTransfers& t) {
  std::set<int> r1s;
  std::set<std::pair<int, int>> groups;
  for (int s = 0; s < t.consumed; ++s) {
    const int o = t.target[static_cast<size_t>(s)], d = s - o, layer = t.layer[static_cast<size_t>(s)];
    if (o == s && layer == 0) continue;
    const int r2 = std::abs(d) <= kMaxRack ? d : (d > 0 ? kMaxRack : -kMaxRack);
    r1s.insert(r2 - d);
    groups.insert({r2, layer});
  }
  return r1s.size() + groups.size();
}

// Whether the row fits the bound's scheme without shuttling: near stitches to b(s) at rack 0,
// each stitch moving 5-8 needles to the first free back needle that reaches (smallest |r1|).
bool fits_without_shuttle(const RowTransfers& t) {
  std::set<int> used;  // back needles as positions s + r1
  std::vector<int> mid;
  for (int s = 0; s < t.consumed; ++s) {
    const int o = t.target[static_cast<size_t>(s)], d = s - o;
    if (o == s && t.layer[static_cast<size_t>(s)] == 0) continue;
    if (std::abs(d) > 2 * kMaxRack) return false;
    if (std::abs(d) <= kMaxRack)
      used.insert(s);
    else
      mid.push_back(s);
  }
  for (int s : mid) {
    const int d = s - t.target[static_cast<size_t>(s)];
    bool placed = false;
    for (int a = 0; a <= kMaxRack && !placed; ++a)
      for (int r : {-a, a})
        if (!placed && std::abs(d + r) <= kMaxRack && !used.count(s + r)) placed = used.insert(s + r).second;
    if (!placed) return false;
  }
  return true;
}

// Loop-level reading of the schedule on needles numbered as the header says (right - s):
// every front needle ends with its output stitch's stack, bottom first, the back bed empty.
// A stitch may cross more than once (far stitches); it never lands on a needle holding loops
// other than its own stack's.
void expect_stacks(const RowTransfers& t, const VbedRowSchedule& plan) {
  const int right = 1000;
  std::map<int, std::vector<int>> front, back;
  for (int s = 0; s < t.consumed; ++s) front[right - s] = {s};
  std::map<int, int> at;  // stitch -> needle it is on now
  std::map<int, bool> on_front;
  for (int s = 0; s < t.consumed; ++s) at[s] = right - s, on_front[s] = true;
  const int width = std::max(t.consumed, t.produced);
  for (const VbedPass& p : plan.passes) {
    EXPECT_LE(std::abs(p.rack), kMaxRack);
    std::set<int> used;
    for (int s : p.stitches) {
      EXPECT_TRUE(used.insert(s).second) << "a stitch twice in one pass";
      ASSERT_EQ(on_front[s], p.to_back) << "stitch " << s << " is not on the bed this pass takes from";
      const int x = at[s];
      auto& from = p.to_back ? front[x] : back[x];
      ASSERT_EQ(from.size(), 1u) << "stitch " << s << " should lie alone while moving";
      ASSERT_EQ(from.front(), s);
      const int y = p.to_back ? x - p.rack : x + p.rack;  // at rack R, f(x) faces b(x - R)
      EXPECT_GE(right - y, -kMaxRack) << "off the bed's margin";
      EXPECT_LE(right - y, width - 1 + kMaxRack) << "off the bed's margin";
      auto& to = p.to_back ? back[y] : front[y];
      if (p.to_back) {
        ASSERT_TRUE(to.empty()) << "two stitches on b" << y;
      } else if (y != right - t.target[static_cast<size_t>(s)]) {
        ASSERT_TRUE(to.empty()) << "stitch " << s << " passing through f" << y << " joins other loops";
      }
      to.insert(to.end(), from.begin(), from.end());
      from.clear();
      at[s] = y;
      on_front[s] = !p.to_back;
    }
  }
  for (const auto& [x, loops] : back) EXPECT_TRUE(loops.empty()) << "b" << x;
  for (int o = 0; o < t.produced; ++o) EXPECT_EQ(front[right - o], t.stack[static_cast<size_t>(o)]) << "stitch " << o;
  for (const auto& [x, loops] : front) {
    if (right - x >= t.produced) {
      EXPECT_TRUE(loops.empty()) << "f" << x << " should be empty";
    }
  }
}

TEST(VbedTransfers, FeatherAndFanTakesOnePassPerRacking) {
  const RowTransfers t = row_transfers(tile_row(test::feather_and_fan_chart().rows[1], 3));
  const VbedRowSchedule plan = schedule_vbed_row(t, kMaxRack);
  ASSERT_TRUE(plan.ok);
  expect_stacks(t, plan);
  EXPECT_LE(plan.passes.size(), pass_bound(t));
  std::set<int> racks;  // of the back-to-front passes: the offsets the row needs
  for (const VbedPass& p : plan.passes)
    if (!p.to_back) racks.insert(p.rack);
  EXPECT_LE(plan.passes.size(), 1 + 2 * racks.size());
}

TEST(VbedTransfers, DecreasesStackInTheirOrderAndStayingBottomsDoNotMove) {
  for (const Row& r : {row({"k", "k2tog", "yo", "k"}), row({"yo", "ssk", "k"}), row({"k", "yo", "sk2p", "yo", "k"}),
                       row({"k2tog", "k2tog", "yo", "yo"})}) {
    const RowTransfers t = row_transfers(r);
    const VbedRowSchedule plan = schedule_vbed_row(t, kMaxRack);
    ASSERT_TRUE(plan.ok);
    expect_stacks(t, plan);
    EXPECT_LE(plan.passes.size(), pass_bound(t));
  }
  const VbedRowSchedule none = schedule_vbed_row(row_transfers(test::knit(5)), kMaxRack);
  EXPECT_TRUE(none.ok);
  EXPECT_TRUE(none.passes.empty());
}

TEST(VbedTransfers, RandomRowsEndInTheirStacksWithinTheBound) {
  std::mt19937 rng(7);
  const char* names[] = {"k", "k", "k", "yo", "k2tog", "ssk", "sk2p"};
  int ok = 0;
  for (int i = 0; i < 400; ++i) {
    Row r;
    const int n = 4 + static_cast<int>(rng() % 12);
    for (int j = 0; j < n; ++j) r.push_back(parse_symbol(names[rng() % 7]));
    const RowTransfers t = row_transfers(r);
    const VbedRowSchedule plan = schedule_vbed_row(t, kMaxRack);
    if (!plan.ok) continue;
    ++ok;
    expect_stacks(t, plan);
    if (fits_without_shuttle(t)) {
      EXPECT_LE(plan.passes.size(), pass_bound(t));
    }
  }
  // Rows moving a stitch more than 8 needles are scheduled too (shuttled across the beds in
  // rounds), so nearly every row is grouped; the rest would be routed in hops by the writer.
  EXPECT_EQ(ok, 400) << ok << " of 400 rows scheduled";
}

// A row widening by 2 stitches per repeat, 6 repeats: the last repeat's stitches move 11
// needles (9 and 7 before it). The far ones shuttle across together, one pass per racking.
TEST(VbedTransfers, FarMovesOfATiledRowAreGroupedPasses) {
  for (const Row& r : {row({"yo", "k", "k", "k", "k", "yo"}), row({"k2tog", "k", "k", "ssk"}),
                       row({"yo", "k", "yo", "k", "yo", "k", "k"})}) {
    const RowTransfers t = row_transfers(tile_row(r, 6));
    int longest = 0;
    for (int s = 0; s < t.consumed; ++s) longest = std::max(longest, std::abs(s - t.target[static_cast<size_t>(s)]));
    EXPECT_GT(longest, 2 * kMaxRack);
    const VbedRowSchedule plan = schedule_vbed_row(t, kMaxRack);
    ASSERT_TRUE(plan.ok);
    expect_stacks(t, plan);
    // Measured 7, 21 and 13 passes (the hop routing took 40-70 for such rows).
    EXPECT_LE(plan.passes.size(), 21u);
  }
}

}  // namespace
}  // namespace atelier::lace
