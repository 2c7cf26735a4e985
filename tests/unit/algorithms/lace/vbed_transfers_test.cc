// [i22-knitout] schedule_vbed_row: few transfer passes (grouped by racking), and the loops end
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

// The bound: the pass to the back, then one pass per (offset, layer) of the moving stitches.
size_t pass_bound(const RowTransfers& t) {
  std::set<std::pair<int, int>> groups;
  for (int s = 0; s < t.consumed; ++s) {
    const int o = t.target[static_cast<size_t>(s)];
    if (o != s || t.layer[static_cast<size_t>(s)] > 0) groups.insert({s - o, t.layer[static_cast<size_t>(s)]});
  }
  return groups.empty() ? 0 : 1 + groups.size();
}

// Loop-level reading of the schedule on needles numbered as the header says (right - s):
// every front needle ends with its output stitch's stack, bottom first, the back bed empty.
void expect_stacks(const RowTransfers& t, const VbedRowSchedule& plan) {
  const int right = 1000;
  std::map<int, std::vector<int>> front, back;
  for (int s = 0; s < t.consumed; ++s) front[right - s] = {s};
  for (const VbedPass& p : plan.passes) {
    EXPECT_LE(std::abs(p.rack), kMaxRack);
    std::set<int> used;
    for (int s : p.stitches) {
      EXPECT_TRUE(used.insert(s).second) << "a stitch twice in one pass";
      const int x = right - s;
      if (p.to_back) {
        ASSERT_FALSE(front[x].empty());
        back[x] = front[x];
        front[x].clear();
      } else {
        ASSERT_FALSE(back[x].empty()) << "stitch " << s << " is not on the back";
        const int to = x + p.rack;  // at rack R, b(x) faces f(x + R)
        EXPECT_EQ(to, right - t.target[static_cast<size_t>(s)]);
        front[to].insert(front[to].end(), back[x].begin(), back[x].end());
        back[x].clear();
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
    for (int s = 0; s < t.consumed; ++s) far = far || std::abs(s - t.target[static_cast<size_t>(s)]) > kMaxRack;
    EXPECT_EQ(plan.ok, !far);
    if (!plan.ok) continue;
    ++ok;
    expect_stacks(t, plan);
    EXPECT_LE(plan.passes.size(), pass_bound(t));
  }
  EXPECT_GT(ok, 150);  // the rest move further than rack 4 (routed in hops)
}

}  // namespace
}  // namespace atelier::lace
