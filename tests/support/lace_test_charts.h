// Lace charts drawn in tests, shared by the lace test files: rows written as a knitter reads
// them, hand-made charts several tests knit, and the fabric a hand knitter makes from a chart.
// Header-only (inline), no state; rows are in knitting order as algorithms/lace/chart.h says.
#pragma once

#include <cstddef>
#include <initializer_list>
#include <vector>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/symbols.h"

namespace atelier::lace::test {

// Rows written as a knitter reads them ("k2, yo, k2tog" -> k, k, yo, k2tog), repeated `times`.
// Throws (parse_symbol) on a name that is not a symbol.
inline Row row(std::initializer_list<const char*> cells, int times = 1) {
  Row r;
  for (int t = 0; t < times; ++t) {
    for (const char* c : cells) r.push_back(parse_symbol(c));
  }
  return r;
}

// `n` plain stitches.
inline Row knit(int n) { return Row(static_cast<std::size_t>(n), Symbol::k); }

// The parts one after the other, as a knitter works them.
inline Row cat(std::initializer_list<Row> parts) {
  Row r;
  for (const Row& p : parts) r.insert(r.end(), p.begin(), p.end());
  return r;
}

// Feather and fan (Old Shale) over 18 stitches: a plain row, then
// "(k2tog) x3, (yo, k1) x6, (k2tog) x3".
inline Chart feather_and_fan_chart() {
  return Chart{{knit(18), cat({row({"k2tog"}, 3), row({"yo", "k"}, 6), row({"k2tog"}, 3)})}};
}

// Horseshoe lace over 10 stitches: yarn-overs walking in towards a central double decrease.
inline Chart horseshoe_chart() {
  return Chart{{
      row({"yo", "k", "k", "k", "sk2p", "k", "k", "k", "yo", "k"}),
      row({"k", "yo", "k", "k", "sk2p", "k", "k", "yo", "k", "k"}),
      row({"k", "k", "yo", "k", "sk2p", "k", "yo", "k", "k", "k"}),
      row({"k", "k", "k", "yo", "sk2p", "yo", "k", "k", "k", "k"}),
  }};
}

// What a hand knitter makes: per chart row, per stitch (knitting order), the stitches of the row
// below it is worked through, bottom first (k2tog: first under second; ssk: second under first;
// sk2p: the middle, then the third, the first on top; s2kp: the third, the first, the middle
// on top). Stitches of the row below are counted
// from 0 across the whole width, all repeats side by side.
using Fabric = std::vector<std::vector<std::vector<int>>>;  // row -> stitch -> stack

// One chart row worked `times` side by side.
inline std::vector<std::vector<int>> expected_row(const Row& r, int times) {
  std::vector<std::vector<int>> out;
  int s = 0;
  for (int t = 0; t < times; ++t) {
    for (Symbol sym : r) {
      switch (sym) {
        case Symbol::yo: out.push_back({}); break;
        case Symbol::k: out.push_back({s}); s += 1; break;
        case Symbol::k2tog: out.push_back({s, s + 1}); s += 2; break;
        case Symbol::ssk: out.push_back({s + 1, s}); s += 2; break;
        case Symbol::sk2p: out.push_back({s + 1, s + 2, s}); s += 3; break;
        case Symbol::s2kp: out.push_back({s + 2, s, s + 1}); s += 3; break;
      }
    }
  }
  return out;
}

// The chart repeated `repeats_wide` side by side and `repeats_high` on top of itself.
inline Fabric expected_fabric(const Chart& c, int repeats_wide, int repeats_high) {
  Fabric f;
  for (int v = 0; v < repeats_high; ++v) {
    for (const Row& r : c.rows) f.push_back(expected_row(r, repeats_wide));
  }
  return f;
}

}  // namespace atelier::lace::test
