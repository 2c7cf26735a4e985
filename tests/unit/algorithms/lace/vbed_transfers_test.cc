// schedule_vbed_row: few transfer passes (grouped by racking), and the loops end
// where row_transfers says, in its stacking order.
#include <gtest/gtest.h>

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

// Loop-level reading of the schedule on needles numbered as the header says (right - s):
// every front needle ends with its output stitch's stack, bottom first, the back bed empty.
void expect_stacks(const RowTransfers& t, const VbedRowSchedule& plan) {
  const int right = 1000;
  std::map<int, std::vector<int>> front, back;
  for (int s = 0; s < t.consumed; ++s) front[right - s] = {s};
  std::map<int, int> on_back;  // stitch -> back needle
  for (const VbedPass& p : plan.passes) {
    EXPECT_LE(std::abs(p.rack), kMaxRack);
    std::set<int> used;
    for (int s : p.stitches) {
      EXPECT_TRUE(used.insert(s).second) << "a stitch twice in one pass";
      if (p.to_back) {
        const int x = right - s;
        ASSERT_FALSE(front[x].empty());
        const int y = x - p.rack;  // at rack R, f(x) faces b(x - R)
        ASSERT_TRUE(back[y].empty()) << "two stitches on b" << y;
        back[y] = front[x];
        front[x].clear();
        on_back[s] = y;
      } else {
        ASSERT_TRUE(on_back.count(s)) << "stitch " << s << " is not on the back";
        const int y = on_back[s];
        ASSERT_FALSE(back[y].empty());
        const int to = y + p.rack;  // b(y) faces f(y + R)
        EXPECT_EQ(to, right - t.target[static_cast<size_t>(s)]);
        front[to].insert(front[to].end(), back[y].begin(), back[y].end());
        back[y].clear();
      }
    }
  }
  for (const auto& [x, loops] : back) EXPECT_TRUE(loops.empty()) << "b" << x;
  for (int o = 0; o < t.produced; ++o) EXPECT_EQ(front[right - o], t.stack[static_cast<size_t>(o)]) << "stitch " << o;
  for (const auto& [x, loops] : front)
    if (right - x >= t.produced) EXPECT_TRUE(loops.empty()) << "f" << x << " should be empty";
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
    bool far = false;
    for (int s = 0; s < t.consumed; ++s) far = far || std::abs(s - t.target[static_cast<size_t>(s)]) > 2 * kMaxRack;
    if (far) EXPECT_FALSE(plan.ok);
    if (!plan.ok) continue;
    ++ok;
    expect_stacks(t, plan);
    EXPECT_LE(plan.passes.size(), pass_bound(t));
  }
  EXPECT_GT(ok, 200);  // the rest move further than 8 needles or share a back needle (routed in hops)
}

}  // namespace
}  // namespace atelier::lace
