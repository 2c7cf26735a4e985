#include "algorithms/lace/symbols.h"

#include <stdexcept>

namespace atelier::lace {

int consumes(Symbol s) {
  switch (s) {
    case Symbol::k: return 1;
    case Symbol::yo: return 0;
    case Symbol::k2tog: return 2;
    case Symbol::ssk: return 2;
    case Symbol::sk2p: return 3;
    case Symbol::s2kp: return 3;
  }
  throw std::invalid_argument("lace: unknown symbol value");
}

int top_stitch(Symbol s) {
  switch (s) {
    case Symbol::k: return 0;
    case Symbol::yo: return 0;
    case Symbol::k2tog: return 1;
    case Symbol::ssk: return 0;
    case Symbol::sk2p: return 0;
    case Symbol::s2kp: return 1;
  }
  throw std::invalid_argument("lace: unknown symbol value");
}

int lean(Symbol s) {
  switch (s) {
    case Symbol::k:
    case Symbol::yo:
    case Symbol::s2kp: return 0;
    case Symbol::k2tog: return 1;
    case Symbol::ssk:
    case Symbol::sk2p: return -1;
  }
  throw std::invalid_argument("lace: unknown symbol value");
}

bool is_decrease(Symbol s) { return consumes(s) >= 2; }

std::string_view name(Symbol s) {
  switch (s) {
    case Symbol::k: return "k";
    case Symbol::yo: return "yo";
    case Symbol::k2tog: return "k2tog";
    case Symbol::ssk: return "ssk";
    case Symbol::sk2p: return "sk2p";
    case Symbol::s2kp: return "s2kp";
  }
  throw std::invalid_argument("lace: unknown symbol value");
}

Symbol parse_symbol(std::string_view text) {
  for (Symbol s : kAllSymbols) {
    if (name(s) == text) return s;
  }
  throw std::invalid_argument("lace: unknown stitch symbol \"" + std::string(text) +
                              "\" (known: k, yo, k2tog, ssk, sk2p, s2kp)");
}

}  // namespace atelier::lace
