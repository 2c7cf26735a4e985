// Checks shared by the DST, EXP and stitch-plan tests: a plan walked against the decoded
// records, and a design with everything in it.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "algorithms/embroidery/stitch_plan.h"
#include "tests/support/stitch_file_readers.h"

namespace atelier::embroidery::test {

// ---- Checks shared by both formats --------------------------------------------------------
// Walks the plan against the decoded records (trims folded): every stitch and jump of the plan
// is reached by one or more records of its kind, each within +-max_units, of near-equal size
// (pieces of one move differ by at most 1 unit), ending within 0.05 mm of the plan's absolute
// position (image y = -file y); trims and colour changes appear in order. Returns the index of
// the first record not consumed.
inline size_t expect_round_trip(const StitchPlan& plan, const std::vector<Rec>& recs, int max_units) {
  size_t k = 0;
  long x = 0, y = 0;  // accumulated file units
  int moves_checked = 0;
  for (size_t p = 0; p < plan.points.size(); ++p) {
    const StitchPoint& pt = plan.points[p];
    if (pt.kind == StitchKind::end) continue;
    if (pt.kind == StitchKind::trim || pt.kind == StitchKind::color_change) {
      const Ev want = pt.kind == StitchKind::trim ? Ev::trim : Ev::color;
      EXPECT_LT(k, recs.size()) << "point " << p;
      if (k >= recs.size()) return k;
      EXPECT_EQ(static_cast<int>(recs[k].type), static_cast<int>(want)) << "point " << p;
      ++k;
      continue;
    }
    const Ev want = pt.kind == StitchKind::stitch ? Ev::stitch : Ev::jump;
    int min_dx = 1 << 20, max_dx = -(1 << 20), min_dy = 1 << 20, max_dy = -(1 << 20);
    bool reached = false;
    while (!reached) {
      EXPECT_LT(k, recs.size()) << "point " << p << " never reached";
      if (k >= recs.size()) return k;
      const Rec& r = recs[k++];
      EXPECT_EQ(static_cast<int>(r.type), static_cast<int>(want)) << "point " << p;
      EXPECT_LE(std::abs(r.dx), max_units);
      EXPECT_LE(std::abs(r.dy), max_units);
      min_dx = std::min(min_dx, r.dx), max_dx = std::max(max_dx, r.dx);
      min_dy = std::min(min_dy, r.dy), max_dy = std::max(max_dy, r.dy);
      x += r.dx;
      y += r.dy;
      reached = std::abs(x / 10.0 - pt.x_mm) <= 0.05 + 1e-9 &&
                std::abs(-y / 10.0 - pt.y_mm) <= 0.05 + 1e-9;
    }
    EXPECT_LE(max_dx - min_dx, 1) << "unequal pieces for point " << p;
    EXPECT_LE(max_dy - min_dy, 1) << "unequal pieces for point " << p;
    ++moves_checked;
  }
  EXPECT_GT(moves_checked, 0);
  return k;
}

// A design with everything: a start run, a 30 mm stitch, 100 tiny stitches whose moves round
// badly (0.26 mm each), a trim, a 40 mm jump, two colour changes, negative coordinates.
inline StitchPlan mixed_plan() {
  StitchPlan plan;
  plan.name = "test design";
  plan.colors_rgb = {0xff0000, 0x00ff00, 0x0000ff};
  auto add = [&](double x, double y, StitchKind k = StitchKind::stitch) {
    plan.points.push_back({x, y, k});
  };
  add(1, 1);
  add(2.5, 1);
  add(32.5, 1);  // 30 mm: 300 units, split in DST and EXP
  for (int i = 1; i <= 100; ++i) add(32.5 + 0.26 * i, 1 + 0.13 * i);  // ends at 58.5, 14
  add(0, 0, StitchKind::trim);
  add(58.5, 54, StitchKind::jump);  // 40 mm jump straight down
  add(0, 0, StitchKind::color_change);
  add(57, 55);
  add(-10.04, 60.06);
  add(0, 0, StitchKind::trim);
  add(-20, -5, StitchKind::jump);
  add(0, 0, StitchKind::color_change);
  add(-21.5, -5);
  add(-21.5, -6.5);
  add(0, 0, StitchKind::end);
  return plan;
}

}  // namespace atelier::embroidery::test
