// A hand-drawn chart shared by the chart and stitch-tree tests.
#pragma once

#include "algorithms/lace/chart.h"
#include "tests/support/lace_test_charts.h"

namespace atelier::lace::test {

// Staggered eyelets over 8 stitches: plain rows between rows of "k2, yo, k2tog" and
// "yo, k2tog, k2", two repeats each.
inline Chart eyelet_chart() {
  return Chart{{knit(8), row({"k", "k", "yo", "k2tog"}, 2), knit(8), row({"yo", "k2tog", "k", "k"}, 2)}};
}

}  // namespace atelier::lace::test
