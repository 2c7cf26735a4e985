// Lace symbols (algorithms/lace/symbols.h, Ekart 2007): what each consumes, their names, and
// parsing.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "algorithms/lace/symbols.h"

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
