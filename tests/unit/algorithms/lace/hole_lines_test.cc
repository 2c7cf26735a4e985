// Holes in lines (algorithms/lace/hole_lines.h): the column layout, lines of eyelets score 1,
// a random mesh of holes at classic lace's density scores low.
#include <gtest/gtest.h>

#include <random>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/hole_lines.h"
#include "tests/support/lace_test_charts.h"

namespace atelier::lace {
namespace {

using namespace test;  // row(), knit(), cat()

// A random mesh: each row strung from k and, with probability q, "yo, k2tog" or "ssk, yo"
// (feasible, constant width), so the holes are placed with no plan.
Chart random_mesh(int width, int rows, double q, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0, 1);
  Chart c;
  for (int r = 0; r < rows; ++r) {
    Row out;
    while (static_cast<int>(out.size()) < width) {
      if (static_cast<int>(out.size()) <= width - 2 && u(rng) < q) {
        if (u(rng) < 0.5) out.insert(out.end(), {Symbol::yo, Symbol::k2tog});
        else out.insert(out.end(), {Symbol::ssk, Symbol::yo});
      } else {
        out.push_back(Symbol::k);
      }
    }
    c.rows.push_back(out);
  }
  return c;
}

TEST(LaceHoleLines, ColumnsSitOverTheStitchesBelow) {
  // "k, yo, k2tog, k" over 4: the yarn-over between cast-on stitches 0 and 1, the k2tog over 1-2.
  const Chart chart{{row({"k", "yo", "k2tog", "k"}), knit(4)}};
  const auto cols = stitch_columns(chart, 4);
  ASSERT_EQ(cols.size(), 2u);
  EXPECT_EQ(cols[0], (std::vector<double>{0, 0.5, 1.5, 3}));
  EXPECT_EQ(cols[1], cols[0]);  // plain stitches stay in their column
  EXPECT_THROW(stitch_columns(chart, 5), std::invalid_argument);
}

TEST(LaceHoleLines, DiagonalLineOfEyeletsIsOneLine) {
  // "yo, k2tog" moving one stitch along each row: one diagonal line of 6 holes.
  Chart diagonal;
  for (int r = 0; r < 6; ++r) diagonal.rows.push_back(cat({knit(r), row({"yo", "k2tog"}), knit(6 - r)}));
  const HoleLines h = hole_lines(diagonal, 8);
  EXPECT_EQ(h.yarn_overs, 6);
  EXPECT_EQ(h.in_lines, 6);
  EXPECT_DOUBLE_EQ(h.hole_lines, 1.0);
  EXPECT_DOUBLE_EQ(h.connectedness, 1.0);
  EXPECT_DOUBLE_EQ(h.yo_share, 6.0 / 48);
}

TEST(LaceHoleLines, ScatteredHolesAreNotLines) {
  // Eyelets 4 stitches apart from row to row never join; two rows of holes are too short a line.
  const Chart scattered{{row({"yo", "k2tog", "k", "k", "k", "k", "k", "k"}),
                         row({"k", "k", "k", "k", "yo", "k2tog", "k", "k"}),
                         row({"yo", "k2tog", "k", "k", "k", "k", "k", "k"})}};
  const HoleLines h = hole_lines(scattered, 8);
  EXPECT_EQ(h.yarn_overs, 3);
  EXPECT_EQ(h.connected, 0);
  EXPECT_DOUBLE_EQ(h.hole_lines, 0.0);
  const Chart pair{{row({"k", "yo", "k2tog", "k"}), row({"k", "yo", "k2tog", "k"})}};
  EXPECT_DOUBLE_EQ(hole_lines(pair, 4).connectedness, 1.0);
  EXPECT_DOUBLE_EQ(hole_lines(pair, 4).hole_lines, 0.0);  // 2 rows: not yet a line
}

TEST(LaceHoleLines, LinesAreFollowedAcrossTheRepeatEdge) {
  // The hole walks off the right of the repeat (knitting order: index 0 is the rightmost
  // stitch) and comes back at the other edge: still one line when tiled.
  const Chart chart{{row({"k", "k", "k", "k", "k", "yo", "k2tog"}), row({"k", "k", "k", "k", "k", "k", "k"}),
                     row({"k", "k", "k", "k", "k", "k", "k"})}};
  EXPECT_DOUBLE_EQ(hole_lines(chart, 7).hole_lines, 0.0);
  const Chart wrap{{row({"k", "k", "k", "k", "k", "ssk", "yo"}), row({"yo", "k2tog", "k", "k", "k", "k", "k"}),
                    row({"k", "yo", "k2tog", "k", "k", "k", "k"})}};
  const HoleLines h = hole_lines(wrap, 7);
  EXPECT_EQ(h.in_lines, 3);
}

// The floor a designed chart clears (evolve_test checks the evolved charts against it).
constexpr double kDesignedHoleLines = 0.8;

TEST(LaceHoleLines, RandomMeshAtLaceDensityScoresBelowTheDesignFloor) {
  std::mt19937_64 rng(3);
  double sum = 0;
  for (int i = 0; i < 20; ++i) {
    const Chart mesh = random_mesh(12, 16, 0.25, rng);
    const HoleLines h = hole_lines(mesh, 12);
    ASSERT_GT(h.yarn_overs, 0);
    EXPECT_LT(h.hole_lines, kDesignedHoleLines) << "mesh " << i;
    sum += h.hole_lines;
  }
  EXPECT_LT(sum / 20, 0.5);
}

}  // namespace
}  // namespace atelier::lace
