// The AYAB lace plan: an independent simulator applies the planned passes to a needle bed of
// loop stacks (lace carriage: the selected stacks move one needle in the pass direction and
// land on top; knit carriage: an empty needle casts on a new loop, a stack becomes one stitch
// whose top is the loop that arrived last) and the knitted fabric must have exactly the
// chart's stitches. Charts the carriage cannot do must come back as problems naming the row.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/symbols.h"
#include "drivers/ayab/lace_plan.h"
#include "tests/support/lace_test_charts.h"

namespace atelier::ayab {
namespace {

using lace::Chart;
using lace::Row;
using lace::Symbol;
using namespace lace::test;  // row(), knit(), expected_fabric() of lace_test_charts.h

// Runs the plan on a simulated bed. Fails the test (and returns what it has) on any breach of
// the carriage rules.
Fabric knit_on_bed(const KnitPlan& plan, int chart_rows_total) {
  const int start = plan.start_needle, width = plan.stop_needle - plan.start_needle + 1;
  // A loop is identified by its index in the row it was made in; the bed holds those indices.
  std::vector<std::vector<int>> bed(static_cast<size_t>(width));
  for (int j = 0; j < width; ++j) bed[static_cast<size_t>(j)] = {j};  // the cast-on
  Fabric fabric;
  EXPECT_EQ(plan.passes.size(), plan.carriage.size());
  EXPECT_EQ(plan.passes.size(), plan.pattern_row.size());
  EXPECT_EQ(plan.passes.size(), plan.colour.size());
  size_t p = 0;
  for (int r = 0; r < chart_rows_total; ++r) {
    int lace = 0;
    while (p < plan.passes.size() && plan.pattern_row[p] == r && plan.carriage[p] == Carriage::lace) {
      const bool ltr = lace % 2 == 0;  // parked left: left to right first
      const int dir = ltr ? 1 : -1;
      std::vector<int> sel;
      for (int n = 0; n < static_cast<int>(plan.passes[p].size()) * 8; ++n)
        if (needle_selected(plan.passes[p], n)) sel.push_back(n);
      for (size_t i = 1; i < sel.size(); ++i)
        EXPECT_GT(sel[i] - sel[i - 1], 1) << "adjacent needles " << sel[i - 1] << ", " << sel[i] << " in pass " << p;
      std::vector<std::pair<int, std::vector<int>>> moves;
      for (int n : sel) {
        const int j = n - start;
        if (j < 0 || j >= width || j + dir < 0 || j + dir >= width) {
          ADD_FAILURE() << "pass " << p << " moves needle " << n << " off the working range";
          return fabric;
        }
        EXPECT_FALSE(bed[static_cast<size_t>(j)].empty()) << "pass " << p << " selects empty needle " << n;
        moves.emplace_back(j + dir, bed[static_cast<size_t>(j)]);
        bed[static_cast<size_t>(j)].clear();
      }
      for (auto& [to, loops] : moves)
        bed[static_cast<size_t>(to)].insert(bed[static_cast<size_t>(to)].end(), loops.begin(), loops.end());
      ++lace;
      ++p;
    }
    EXPECT_EQ(lace % 2, 0) << "chart row " << r << " leaves the lace carriage on the right";
    // Two knit passes with nothing selected: the RS row, then the WS row.
    for (int k = 0; k < 2; ++k) {
      if (p >= plan.passes.size() || plan.pattern_row[p] != r || plan.carriage[p] != Carriage::knit) {
        ADD_FAILURE() << "chart row " << r << " lacks its knit-carriage pass " << k;
        return fabric;
      }
      for (int n = 0; n < static_cast<int>(plan.passes[p].size()) * 8; ++n)
        EXPECT_FALSE(needle_selected(plan.passes[p], n)) << "knit pass " << p << " selects needle " << n;
      std::vector<std::vector<int>> made;
      for (int j = 0; j < width; ++j) {
        made.push_back(bed[static_cast<size_t>(j)]);
        bed[static_cast<size_t>(j)] = {j};
      }
      if (k == 0) {
        fabric.push_back(made);
      } else {
        for (int j = 0; j < width; ++j) EXPECT_EQ(made[static_cast<size_t>(j)], std::vector<int>{j}) << "WS row";
      }
      ++p;
    }
  }
  EXPECT_EQ(p, plan.passes.size()) << "passes left over";
  return fabric;
}

void expect_knits(const Chart& chart, int cast_on, int repeats_wide, int repeats_high, PlanParams params = {}) {
  const LacePlanResult res = plan_lace(chart, cast_on, repeats_wide, repeats_high, params);
  ASSERT_TRUE(res.problems.empty()) << res.problems.front();
  ASSERT_TRUE(res.plan.has_value());
  const KnitPlan& plan = *res.plan;
  EXPECT_EQ(plan.stop_needle - plan.start_needle + 1, cast_on * repeats_wide);
  const int total = static_cast<int>(chart.rows.size()) * repeats_high;
  EXPECT_EQ(res.knit_passes, 2 * total);
  EXPECT_EQ(res.lace_passes + res.knit_passes, static_cast<int>(plan.passes.size()));
  for (size_t i = 1; i < plan.pattern_row.size(); ++i) EXPECT_LE(plan.pattern_row[i - 1], plan.pattern_row[i]);
  EXPECT_EQ(plan.pattern_row.back(), total - 1);
  EXPECT_EQ(knit_on_bed(plan, total), expected_fabric(chart, repeats_wide, repeats_high));
}

bool mentions(const std::vector<std::string>& problems, const std::string& a, const std::string& b = "") {
  for (const auto& p : problems)
    if (p.find(a) != std::string::npos && p.find(b) != std::string::npos) return true;
  return false;
}

TEST(AyabLacePlan, K2togThenYarnOver) {
  expect_knits(Chart{{knit(6), row({"k", "k2tog", "yo", "k", "k", "k"})}}, 6, 1, 1);
  expect_knits(Chart{{knit(6), row({"k", "k2tog", "yo", "k", "k", "k"})}}, 6, 3, 2);
}

TEST(AyabLacePlan, YarnOverThenSsk) {
  expect_knits(Chart{{row({"k", "yo", "ssk", "k"}), knit(4)}}, 4, 4, 3);
}

TEST(AyabLacePlan, PlainStitchesShiftBetweenYarnOverAndDecrease) {
  const Chart right{{row({"yo", "k", "k", "k", "ssk", "k"}), knit(6)}};
  const Chart left{{row({"k", "k2tog", "k", "k", "k", "yo"}), knit(6)}};
  expect_knits(right, 6, 2, 2);
  expect_knits(left, 6, 2, 2);
  // Three stitches shifted one needle at a time: more passes than a neighbouring pair.
  const auto near = plan_lace(Chart{{row({"k", "k", "k", "yo", "ssk", "k"})}}, 6, 1, 1, {});
  const auto far = plan_lace(right, 6, 1, 1, {});
  ASSERT_TRUE(near.plan && far.plan);
  EXPECT_GT(far.lace_passes, near.lace_passes);
}

TEST(AyabLacePlan, DoubleDecreaseWithYarnOverEitherSide) {
  expect_knits(Chart{{row({"k", "yo", "sk2p", "yo", "k"}), knit(5)}}, 5, 3, 2);
  // Horseshoe-like: the yarn-overs walk away from the double decrease.
  expect_knits(Chart{{row({"yo", "k", "k", "sk2p", "k", "k", "yo", "k"}), knit(8)}}, 8, 2, 1);
}

TEST(AyabLacePlan, RepeatsSideBySideDoNotDisturbEachOther) {
  // The yarn-over at the end of one repeat sits next to the k2tog that opens the next.
  expect_knits(Chart{{row({"k2tog", "k", "k", "yo"}), row({"yo", "ssk", "k", "k"})}}, 4, 5, 2);
  expect_knits(Chart{{row({"k2tog", "yo"}), row({"yo", "ssk"})}}, 2, 7, 3);
}

TEST(AyabLacePlan, StartNeedleAndCentring) {
  const Chart c{{row({"k2tog", "yo", "k", "k"})}};
  const auto centred = plan_lace(c, 4, 10, 1, {});
  ASSERT_TRUE(centred.plan);
  EXPECT_EQ(centred.plan->start_needle, 80);  // (200 - 40) / 2
  EXPECT_EQ(centred.plan->stop_needle, 119);
  PlanParams p;
  p.start_needle = 3;
  expect_knits(c, 4, 10, 2, p);
  const auto placed = plan_lace(c, 4, 10, 1, p);
  ASSERT_TRUE(placed.plan);
  EXPECT_EQ(placed.plan->start_needle, 3);
  // The pass that carries the yarn-over's neighbour: stitch 1 of each repeat moves onto stitch 0.
  bool saw = false;
  for (size_t i = 0; i < placed.plan->passes.size(); ++i)
    if (placed.plan->carriage[i] == Carriage::lace && needle_selected(placed.plan->passes[i], 3 + 1)) saw = true;
  EXPECT_TRUE(saw);
  EXPECT_NE(placed.plan->note.front().find("lace carriage"), std::string::npos);
  EXPECT_NE(placed.plan->note.back().find("knit carriage"), std::string::npos);
}

// Random charts built from pieces the lace carriage can do: plain stitches, "k2tog, k.., yo",
// "yo, k.., ssk", "yo, sk2p, yo", in any order, each row balanced.
Row feasible_row(std::mt19937& rng, int pieces) {
  Row r;
  std::uniform_int_distribution<int> kind(0, 3), run(0, 2);
  for (int i = 0; i < pieces; ++i) {
    const int n = run(rng);
    switch (kind(rng)) {
      case 0: r.push_back(Symbol::k); break;
      case 1:
        r.push_back(Symbol::k2tog);
        r.insert(r.end(), static_cast<size_t>(n), Symbol::k);
        r.push_back(Symbol::yo);
        break;
      case 2:
        r.push_back(Symbol::yo);
        r.insert(r.end(), static_cast<size_t>(n), Symbol::k);
        r.push_back(Symbol::ssk);
        break;
      default: r.insert(r.end(), {Symbol::yo, Symbol::sk2p, Symbol::yo}); break;
    }
  }
  return r;
}

TEST(AyabLacePlan, RandomFeasibleChartsKnitExactly) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 60; ++trial) {
    // Every row the same width: build one, then fill the others with pieces up to that width.
    const Row first = feasible_row(rng, 4);
    const int w = static_cast<int>(first.size());
    Chart c{{first}};
    for (int r = 1; r < 4; ++r) {
      Row next;
      while (static_cast<int>(next.size()) < w) {
        Row piece = feasible_row(rng, 1);
        if (static_cast<int>(next.size() + piece.size()) > w) piece = knit(1);
        next.insert(next.end(), piece.begin(), piece.end());
      }
      c.rows.push_back(next);
    }
    SCOPED_TRACE("trial " + std::to_string(trial));
    expect_knits(c, w, 1 + trial % 3, 2);
  }
}

TEST(AyabLacePlan, WidthChangeIsAProblemNamingTheRow) {
  const Chart c{{knit(4), row({"yo", "k", "k", "k", "k"}), row({"k2tog", "k", "k", "k"})}};
  const auto res = plan_lace(c, 4, 2, 1, {});
  EXPECT_FALSE(res.plan);
  EXPECT_TRUE(mentions(res.problems, "row 3 (RS)", "width")) << res.problems.front();
  EXPECT_TRUE(mentions(res.problems, "row 5 (RS)", "width"));
  EXPECT_FALSE(mentions(res.problems, "row 1 (RS)"));
}

TEST(AyabLacePlan, YarnOverBeforeK2togIsAProblem) {
  const Chart c{{knit(4), row({"k", "yo", "k2tog", "k"})}};
  const auto res = plan_lace(c, 4, 3, 2, {});
  EXPECT_FALSE(res.plan);
  ASSERT_EQ(res.problems.size(), 1u);  // once, not per repeat
  EXPECT_TRUE(mentions(res.problems, "row 3 (RS)", "stitch 3 (k2tog)")) << res.problems.front();
  EXPECT_TRUE(mentions(res.problems, "slant"));
  // The same with plain stitches between, and ssk on the wrong side of its yarn-over.
  EXPECT_FALSE(plan_lace(Chart{{row({"yo", "k", "k", "k", "k2tog"})}}, 5, 1, 1, {}).plan);
  EXPECT_FALSE(plan_lace(Chart{{row({"ssk", "yo"})}}, 2, 1, 1, {}).plan);
  EXPECT_FALSE(plan_lace(Chart{{row({"sk2p", "yo", "yo"})}}, 3, 1, 1, {}).plan);
}

TEST(AyabLacePlan, YarnOverTooFarFromItsDecreaseIsAProblem) {
  const Chart c{{knit(10), row({"yo", "k", "k", "k", "k", "k", "k", "k", "k", "ssk"})}};
  const auto res = plan_lace(c, 10, 1, 1, {});
  EXPECT_FALSE(res.plan);
  EXPECT_TRUE(mentions(res.problems, "row 3 (RS)", "passes")) << res.problems.front();
  EXPECT_TRUE(mentions(res.problems, "more than the 12"));
  // A looser carriage limit lets the same chart through.
  const auto loose = plan_lace(c, 10, 1, 1, {}, lace::CarriageLimits{40});
  ASSERT_TRUE(loose.plan) << loose.problems.front();
  EXPECT_GT(loose.lace_passes, 12);
  EXPECT_EQ(knit_on_bed(*loose.plan, 2), expected_fabric(c, 1, 1));
}

TEST(AyabLacePlan, WiderThanTheBedNamesBothWidths) {
  const Chart c{{row({"k2tog", "yo", "k", "k", "k", "k", "k", "k", "k", "k"})}};
  const auto res = plan_lace(c, 10, 21, 1, {});
  EXPECT_FALSE(res.plan);
  EXPECT_TRUE(mentions(res.problems, "210 stitches", "200 needles")) << res.problems.front();
  PlanParams kh270;
  kh270.machine = MachineType::kh270;
  const auto small = plan_lace(c, 10, 12, 1, kh270);
  EXPECT_TRUE(mentions(small.problems, "120 stitches", "112 needles"));
  EXPECT_TRUE(plan_lace(c, 10, 11, 1, kh270).plan);
}

}  // namespace
}  // namespace atelier::ayab
