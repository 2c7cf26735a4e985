// The lace chart symbols of Ekart 2007 (Fig. 1): what a knitter does at one chart cell.
// Every symbol makes exactly one stitch; they differ in how many stitches of the row below
// they are worked over (consumes) and which way the finished stitch leans (lean).
// The paper's double decrease is centred: that is s2kp (issue 22). sk2p, worked as written,
// leans left; it stays a symbol with that true lean (old chart.json files name it).
// Pure functions, thread-safe.
#pragma once

#include <string>
#include <string_view>

namespace atelier::lace {

enum class Symbol {
  k,      // knit: a plain stitch over 1 stitch
  yo,     // yarn over: a new stitch over 0 stitches (makes a hole)
  k2tog,  // knit 2 together: over 2, slants right (chart "/")
  ssk,    // slip, slip, knit: over 2, slants left (chart "\")
  sk2p,   // slip 1, knit 2 together, pass slipped stitch over: over 3, leans LEFT (the
          // slipped right stitch lies on top)
  s2kp    // slip 2 together knitwise, knit 1, pass the 2 slipped stitches over: over 3, the
          // centred double decrease (the centre stitch on top; chart "^")
};

inline constexpr Symbol kAllSymbols[] = {Symbol::k, Symbol::yo, Symbol::k2tog, Symbol::ssk,
                                         Symbol::sk2p, Symbol::s2kp};

// Stitches of the row below that the symbol is worked over: 1, 0, 2, 2, 3, 3.
int consumes(Symbol s);

// Which of the consumed stitches (0-based, knitting order) lies on top of the finished stitch,
// so the stitch sits over it in a printed chart (chart_layout.h) and leans toward it: k 0,
// k2tog 1 (the left one: leans right), ssk 0 (the right one: leans left), sk2p 0 (the slipped
// stitch passed over, the right one: leans left), s2kp 1 (the centre). 0 for a yarn-over.
int top_stitch(Symbol s);

// Which way the finished stitch leans on the right side: +1 right (k2tog), -1 left (ssk,
// sk2p), 0 upright (k, yo, s2kp).
int lean(Symbol s);

// Whether the symbol decreases (k2tog, ssk, sk2p, s2kp).
bool is_decrease(Symbol s);

// The standard abbreviation: "k", "yo", "k2tog", "ssk", "sk2p", "s2kp".
std::string_view name(Symbol s);

// The symbol whose name() is `text` (exact, lower case). Throws std::invalid_argument naming
// the text for anything else (e.g. "k3tog" is not a symbol of the paper).
Symbol parse_symbol(std::string_view text);

}  // namespace atelier::lace
