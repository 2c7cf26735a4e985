// The lace chart symbols of Ekart 2007 (Fig. 1): what a knitter does at one chart cell.
// Every symbol makes exactly one stitch; they differ in how many stitches of the row below
// they are worked over (consumes). Pure functions, thread-safe.
#pragma once

#include <string>
#include <string_view>

namespace atelier::lace {

enum class Symbol {
  k,      // knit: a plain stitch over 1 stitch
  yo,     // yarn over: a new stitch over 0 stitches (makes a hole)
  k2tog,  // knit 2 together: over 2, slants right (chart "/")
  ssk,    // slip, slip, knit: over 2, slants left (chart "\")
  sk2p    // slip 1, knit 2 together, pass slipped stitch over: over 3, centred double decrease
};

inline constexpr Symbol kAllSymbols[] = {Symbol::k, Symbol::yo, Symbol::k2tog, Symbol::ssk,
                                         Symbol::sk2p};

// Stitches of the row below that the symbol is worked over: 1, 0, 2, 2, 3.
int consumes(Symbol s);

// The standard abbreviation: "k", "yo", "k2tog", "ssk", "sk2p".
std::string_view name(Symbol s);

// The symbol whose name() is `text` (exact, lower case). Throws std::invalid_argument naming
// the text for anything else (e.g. "k3tog" is not a symbol of the paper).
Symbol parse_symbol(std::string_view text);

}  // namespace atelier::lace
