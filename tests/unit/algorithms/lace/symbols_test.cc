// Lace symbols (algorithms/lace/symbols.h, Ekart 2007): what each consumes, their names, and
// parsing.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "algorithms/lace/symbols.h"
#include "algorithms/lace/transfers.h"
#include "convert/lace/lace_chart_json.h"

namespace atelier::lace {
namespace {

TEST(LaceSymbols, ConsumesAndNamesAreThePapers) {
  EXPECT_EQ(consumes(Symbol::k), 1);
  EXPECT_EQ(consumes(Symbol::yo), 0);
  EXPECT_EQ(consumes(Symbol::k2tog), 2);
  EXPECT_EQ(consumes(Symbol::ssk), 2);
  EXPECT_EQ(consumes(Symbol::sk2p), 3);
  for (Symbol s : kAllSymbols) EXPECT_EQ(parse_symbol(name(s)), s);
  EXPECT_EQ(name(Symbol::k2tog), "k2tog");
  EXPECT_EQ(name(Symbol::sk2p), "sk2p");
  EXPECT_EQ(consumes(Symbol::s2kp), 3);
  EXPECT_EQ(name(Symbol::s2kp), "s2kp");
}

// Issue 22, lace point 2: each decrease with its true lean. sk2p worked as written (slip 1,
// k2tog, pass the slipped stitch over) leans left; the centred double decrease is s2kp.
TEST(LaceSymbols, DecreasesLeanTheirTrueWay) {
  EXPECT_EQ(lean(Symbol::k2tog), 1);
  EXPECT_EQ(lean(Symbol::ssk), -1);
  EXPECT_EQ(lean(Symbol::sk2p), -1);
  EXPECT_EQ(lean(Symbol::s2kp), 0);
  EXPECT_EQ(lean(Symbol::k), 0);
  EXPECT_EQ(top_stitch(Symbol::k2tog), 1);  // the left one of the two (knitting order)
  EXPECT_EQ(top_stitch(Symbol::ssk), 0);
  EXPECT_EQ(top_stitch(Symbol::sk2p), 0);   // the slipped (right) stitch passed over
  EXPECT_EQ(top_stitch(Symbol::s2kp), 1);   // the centre stitch
  for (Symbol s : kAllSymbols) EXPECT_EQ(is_decrease(s), consumes(s) >= 2) << name(s);
}

// The stack each decrease leaves on its needle, bottom first (transfers.h): what the knitout and
// the lace carriage build. The top stitch is the one the decrease leans toward.
TEST(LaceSymbols, StackOrderPerDecrease) {
  auto stack_of = [](Symbol s) { return row_transfers(Row{s}).stack[0]; };
  EXPECT_EQ(stack_of(Symbol::k2tog), (std::vector<int>{0, 1}));     // left (1) on top
  EXPECT_EQ(stack_of(Symbol::ssk), (std::vector<int>{1, 0}));       // right (0) on top
  EXPECT_EQ(stack_of(Symbol::sk2p), (std::vector<int>{1, 2, 0}));   // k2tog, then the right one over
  EXPECT_EQ(stack_of(Symbol::s2kp), (std::vector<int>{2, 0, 1}));   // k1, the 2 slipped over: centre on top
  for (Symbol s : kAllSymbols)
    if (is_decrease(s)) EXPECT_EQ(stack_of(s).back(), top_stitch(s)) << name(s);
}

// Old chart.json files name "sk2p": they keep reading as sk2p, with its true left lean.
TEST(LaceSymbols, OldChartFilesWithSk2pReadAsSk2p) {
  const LaceChartFile f = lace_chart_from_json_text(R"({"rows": [["k", "yo", "sk2p", "yo", "k"]]})", "old.json");
  ASSERT_EQ(f.chart.rows[0][2], Symbol::sk2p);
  EXPECT_EQ(lean(f.chart.rows[0][2]), -1);
  EXPECT_EQ(lace_chart_to_json(f)["rows"][0][2], "sk2p");
}

TEST(LaceSymbols, ParseRejectsUnknownSymbolNamingIt) {
  try {
    parse_symbol("k3tog");
    FAIL() << "k3tog accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("k3tog"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_symbol("K"), std::invalid_argument);
  EXPECT_THROW(parse_symbol(""), std::invalid_argument);
}

}  // namespace
}  // namespace atelier::lace
