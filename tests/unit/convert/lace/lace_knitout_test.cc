// lace.k: a small knitout interpreter runs the file (loops per needle on both beds; xfer moves
// all loops of a needle to the other bed, across at the current rack, on top of what is
// there; knit replaces a needle's loops by a new loop made through them, bottom first) and the
// fabric must be the chart's: per stitch, which stitches of the row below it is made through
// and in which order they lie.
#include <gtest/gtest.h>

#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/symbols.h"
#include "convert/lace/lace_knitout.h"
#include "tests/support/lace_test_charts.h"

namespace atelier {
namespace {

using lace::Chart;
using lace::Row;
using lace::Symbol;
using namespace lace::test;  // row(), knit(), expected_fabric() of lace_test_charts.h

struct KnitRun {
  std::vector<std::string> headers;
  // Knit passes in order: each the loops it made, in knitting order (highest needle first,
  // the right edge seen on the right side), each loop as the ids of the loops it was made
  // through, bottom first.
  struct Pass {
    char dir;
    std::vector<int> ids;                  // loop ids, knitting order
    std::vector<std::vector<int>> through; // per loop
  };
  std::vector<Pass> passes;
  int loops_left = 0;
  int loops_at_bind_off = -1;  // loops on the needles when "; bind-off" starts (-1: none)
};

// Interprets the file; any breach of the rules is a test failure.
KnitRun interpret(const std::string& k) {
  KnitRun run;
  std::map<int, std::vector<int>> front, back;  // needle -> loop ids, bottom first
  int rack = 0, next_id = 0;
  std::istringstream in(k);
  std::string line;
  int lineno = 0;
  bool in_pass = false, binding = false;
  auto end_pass = [&] { in_pass = false; };
  std::map<int, int> made_through_count;  // loop id -> times knitted through
  while (std::getline(in, line)) {
    ++lineno;
    const std::string at = "line " + std::to_string(lineno) + ": " + line;
    if (line.rfind(";;", 0) == 0 || line.rfind(";!", 0) == 0) {
      run.headers.push_back(line);
      continue;
    }
    if (line.rfind("; bind-off", 0) == 0) {  // the rows end; the chain bind-off follows
      binding = true;
      run.loops_at_bind_off = 0;
      for (const auto& [x, loops] : front) run.loops_at_bind_off += static_cast<int>(loops.size());
      for (const auto& [x, loops] : back) run.loops_at_bind_off += static_cast<int>(loops.size());
      continue;
    }
    if (line.empty() || line[0] == ';') continue;
    std::istringstream ls(line);
    std::string op;
    ls >> op;
    auto needle = [&](const std::string& spec, char& bed) {
      bed = spec.at(0);
      return std::stoi(spec.substr(1));
    };
    if (op == "rack") {
      ls >> rack;
      EXPECT_LE(std::abs(rack), 4) << at;
      end_pass();
    } else if (op == "xfer") {
      std::string a, b;
      ls >> a >> b;
      char ba, bb;
      const int na = needle(a, ba), nb = needle(b, bb);
      EXPECT_NE(ba, bb) << at;
      // At rack R, f.x is across b.(x - R).
      const int f = ba == 'f' ? na : nb, bk = ba == 'f' ? nb : na;
      EXPECT_EQ(bk, f - rack) << "needles not aligned at rack " << rack << ": " << at;
      auto& from = ba == 'f' ? front[na] : back[na];
      auto& to = bb == 'f' ? front[nb] : back[nb];
      EXPECT_FALSE(from.empty()) << "transfer from an empty needle: " << at;
      to.insert(to.end(), from.begin(), from.end());
      from.clear();
      end_pass();
    } else if (op == "tuck") {
      std::string dir, spec;
      ls >> dir >> spec;
      char bed;
      const int n = needle(spec, bed);
      EXPECT_EQ(bed, 'f') << at;
      front[n].push_back(next_id++);
    } else if (op == "knit") {
      std::string dir, spec;
      ls >> dir >> spec;
      char bed;
      const int n = needle(spec, bed);
      EXPECT_EQ(bed, 'f') << "lace is knitted on the front bed: " << at;
      for (const auto& [x, loops] : back) EXPECT_TRUE(loops.empty()) << "loops left on b" << x << " at " << at;
      if (binding) {  // binding off: knitted through once each, no fabric pass
        for (int id : front[n]) ++made_through_count[id];
        front[n] = {next_id++};
        continue;
      }
      if (!in_pass || run.passes.back().dir != dir[0]) {
        run.passes.push_back({dir[0], {}, {}});
        in_pass = true;
      }
      auto& pass = run.passes.back();
      if (dir == "-") {
        pass.ids.push_back(next_id);
        pass.through.push_back(front[n]);
      } else {  // rightwards: the knitting order is the reverse
        pass.ids.insert(pass.ids.begin(), next_id);
        pass.through.insert(pass.through.begin(), front[n]);
      }
      for (int id : front[n]) ++made_through_count[id];
      front[n] = {next_id++};
    } else if (op == "drop") {
      std::string spec;
      ls >> spec;
      char bed;
      const int n = needle(spec, bed);
      if (!binding) ADD_FAILURE() << "a loop is dropped: " << at;
      EXPECT_EQ(front[n].size(), 1u) << "the bind-off's last loop only: " << at;
      front[n].clear();
    } else if (op == "inhook" || op == "releasehook" || op == "outhook" || op == "miss") {
      end_pass();
    } else {
      ADD_FAILURE() << "unexpected operation: " << at;
    }
  }
  for (const auto& [id, times] : made_through_count) EXPECT_EQ(times, 1) << "loop " << id << " knitted twice";
  for (const auto& [x, loops] : front) run.loops_left += static_cast<int>(loops.size());
  for (const auto& [x, loops] : back) run.loops_left += static_cast<int>(loops.size());
  return run;
}

// The fabric of the chart rows: each right-side pass's stitches in terms of the stitches of the
// wrong-side (or plain) pass before it; the wrong-side rows must be plain.
Fabric fabric_of(const KnitRun& run) {
  Fabric f;
  for (size_t p = 1; p < run.passes.size(); ++p) {
    const auto& prev = run.passes[p - 1];
    const auto& cur = run.passes[p];
    std::map<int, int> index;  // loop id of the row below -> its knitting-order index
    for (size_t i = 0; i < prev.ids.size(); ++i) index[prev.ids[i]] = static_cast<int>(i);
    std::vector<std::vector<int>> stitches;
    for (const auto& through : cur.through) {
      std::vector<int> s;
      for (int id : through) s.push_back(index.count(id) ? index[id] : -1);
      stitches.push_back(s);
    }
    if (p >= 2 && p % 2 == 0) {
      f.push_back(stitches);  // passes 2, 4, ...: right-side rows (0, 1: the plain rows)
    } else {
      EXPECT_EQ(cur.dir, p % 2 == 1 ? '+' : '-');
      for (size_t i = 0; i < stitches.size(); ++i)
        EXPECT_EQ(stitches[i], std::vector<int>{static_cast<int>(i)}) << "pass " << p << " should be plain";
    }
  }
  return f;
}

void expect_fabric(const Chart& chart, int cast_on, int wide, int high) {
  LaceKnitoutOptions o;
  o.title = "test";
  o.repeats_wide = wide;
  o.repeats_high = high;
  const std::string k = make_lace_knitout(chart, cast_on, o);
  const KnitRun run = interpret(k);
  ASSERT_EQ(run.passes.size(), 2 + 2 * chart.rows.size() * static_cast<size_t>(high));
  EXPECT_EQ(fabric_of(run), expected_fabric(chart, wide, high));
  // Nothing was lost: what is on the needles at the bind-off is the last row; the bind-off
  // leaves nothing.
  EXPECT_EQ(run.loops_at_bind_off, static_cast<int>(run.passes.back().ids.size()));
  EXPECT_EQ(run.loops_left, 0);
}

TEST(LaceKnitout, HeaderLines) {
  const std::string k = make_lace_knitout(Chart{{row({"k2tog", "yo"})}}, 2, {});
  const KnitRun run = interpret(k);
  // The knitout spec's headers only, in the file's first lines (no ;;Width:, which is none).
  EXPECT_EQ(run.headers, (std::vector<std::string>{";!knitout-2", ";;Machine: SWG091N2", ";;Gauge: 7",
                                                   ";;Carriers: 1 2 3 4 5 6 7 8 9 10", ";;Position: Center"}));
  EXPECT_EQ(k.rfind(";!knitout-2\n;;Machine: SWG091N2\n;;Gauge: 7\n;;Carriers: 1 2 3 4 5 6 7 8 9 10\n;;Position: Center\n; carriers used: 1\n", 0), 0u);
  for (const char* op : {"inhook 1", "releasehook 1", "outhook 1", "; row 1\n", "; row 3\n", "rack 1", "rack 0"})
    EXPECT_NE(k.find(op), std::string::npos) << op;
  EXPECT_EQ(k.find("; row 4\n"), std::string::npos);  // 1 chart row x 3 repeats high
}

TEST(LaceKnitout, ATitleWithLineBreaksStaysOneComment) {
  LaceKnitoutOptions o;
  o.title = "swatch\nknit + f1 1\rdrop f2";
  const std::string k = make_lace_knitout(Chart{{row({"k", "k"})}}, 2, o);
  EXPECT_NE(k.find("; swatch knit + f1 1 drop f2\n"), std::string::npos);
  EXPECT_EQ(k.find("\nknit + f1 1\n"), std::string::npos);
  EXPECT_EQ(k.find("\ndrop f2"), std::string::npos);
}

TEST(LaceKnitout, HandMadeChartsKnitTheirStitches) {
  expect_fabric(Chart{{knit(6), row({"k", "k2tog", "yo", "k", "k", "k"})}}, 6, 3, 2);
  // The stacking orders the lace carriage cannot do are plain racking work here.
  expect_fabric(Chart{{row({"k", "yo", "k2tog", "k"}), row({"ssk", "yo", "k", "k"})}}, 4, 3, 2);
  expect_fabric(Chart{{row({"yo", "k", "k", "k", "k2tog"}), row({"ssk", "k", "k", "k", "yo"})}}, 5, 2, 2);
}

TEST(LaceKnitout, DoubleDecreases) {
  expect_fabric(Chart{{row({"k", "yo", "sk2p", "yo", "k"}), knit(5)}}, 5, 3, 2);
  expect_fabric(Chart{{row({"sk2p", "yo", "yo"}), row({"yo", "yo", "sk2p"})}}, 3, 2, 2);
  // Horseshoe: yarn-overs four stitches from their decrease.
  expect_fabric(Chart{{row({"yo", "k", "k", "k", "sk2p", "k", "k", "k", "yo", "k"})}}, 10, 2, 2);
}

TEST(LaceKnitout, WidthChangingRowsAndLongMoves) {
  // Widen by 4, then narrow by 4: stitches travel more than four needles, in hops.
  const Chart c{{row({"yo", "k", "yo", "k", "yo", "k", "yo", "k"}), row({"k2tog", "k2tog", "k2tog", "k2tog"})}};
  expect_fabric(c, 4, 3, 2);
  expect_fabric(Chart{{row({"yo", "yo", "k", "k", "k", "k", "k", "k", "k", "k", "sk2p"})}}, 11, 1, 1);
  const std::string k = make_lace_knitout(c, 4, {});
  EXPECT_EQ(k.find("rack 5"), std::string::npos);
  EXPECT_EQ(k.find("rack -5"), std::string::npos);
}

TEST(LaceKnitout, RandomChartsKnitTheirStitches) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 80; ++trial) {
    const int cast_on = 3 + trial % 8;
    Chart c;
    int below = cast_on;
    for (int r = 0; r < 4; ++r) {
      Row next;
      int left = below, made = 0;
      while (left > 0) {
        Symbol s = lace::kAllSymbols[std::uniform_int_distribution<int>(0, 4)(rng)];
        // Keep every row within a few stitches of the cast-on.
        if (s == Symbol::yo && made - (below - left) >= 3) s = Symbol::k;
        if (lace::consumes(s) > left) s = Symbol::k;
        next.push_back(s);
        left -= lace::consumes(s);
        ++made;
      }
      below = static_cast<int>(next.size());
      c.rows.push_back(next);
    }
    SCOPED_TRACE("trial " + std::to_string(trial));
    // Repeated on top of itself only when the last row is as wide as the cast-on.
    expect_fabric(c, cast_on, 1 + trial % 3, below == cast_on ? 2 : 1);
  }
}

TEST(LaceKnitout, RefusesAChartThatCannotBeKnitted) {
  EXPECT_THROW(make_lace_knitout(Chart{{row({"k2tog", "yo"})}}, 3, {}), std::invalid_argument);
  LaceKnitoutOptions o;
  o.repeats_high = 2;  // a chart that widens cannot sit on top of itself
  EXPECT_THROW(make_lace_knitout(Chart{{row({"yo", "k", "k"})}}, 2, o), std::invalid_argument);
  o.repeats_high = 1;
  EXPECT_NO_THROW(make_lace_knitout(Chart{{row({"yo", "k", "k"})}}, 2, o));
  o.repeats_wide = 0;
  EXPECT_THROW(make_lace_knitout(Chart{{row({"k2tog", "yo"})}}, 2, o), std::invalid_argument);
}

}  // namespace
}  // namespace atelier

namespace atelier {
namespace {
// Transfer passes of each chart row in lace.k: runs of xfers at one racking in
// one direction (front to back or back to front).
std::vector<int> transfer_passes_per_row(const std::string& k) {
  std::vector<int> out;
  std::istringstream in(k);
  std::string line, last;
  int rack = 0;
  while (std::getline(in, line)) {
    if (line.rfind("; row ", 0) == 0) {
      out.push_back(0);
      last.clear();
    } else if (line.rfind("; bind-off", 0) == 0) {
      break;
    } else if (line.rfind("rack ", 0) == 0) {
      rack = std::stoi(line.substr(5));
    } else if (line.rfind("xfer ", 0) == 0 && !out.empty()) {
      const std::string key = std::to_string(rack) + line.substr(5, 1);
      if (key != last) ++out.back();
      last = key;
    } else if (line.rfind("knit ", 0) == 0) {
      last.clear();
    }
  }
  return out;
}

TEST(LaceKnitout, TransfersArePassesGroupedByRacking) {
  const Chart chart = feather_and_fan_chart();
  LaceKnitoutOptions o;
  o.repeats_wide = 3;
  o.repeats_high = 1;
  const std::string k = make_lace_knitout(chart, 18, o);
  const std::vector<int> passes = transfer_passes_per_row(k);
  ASSERT_EQ(passes.size(), 2u);
  EXPECT_EQ(passes[0], 0);
  // (k2tog) x3 moves stitches 0..2 needles right, (yo, k1) x6 shifts up to 3: at most 7
  // offsets; the pass to the back plus at most two passes per racking.
  EXPECT_GE(passes[1], 2);
  EXPECT_LE(passes[1], 1 + 2 * 7);
  expect_fabric(chart, 18, 3, 2);
}
}  // namespace
}  // namespace atelier
