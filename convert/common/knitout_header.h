// The standard knitout header lines both knitout writers (pattern.k, lace.k) start with, so a
// knitout consumer (the SWG knitout-to-dat backend, knitout interpreters, the live visualiser)
// reads them. Only the spec's headers: ;!knitout-2, ;;Machine: an identifier the SWG backend
// knows, ;;Gauge: an integer (needles per inch), ;;Carriers: the machine's carriers left to
// right (the SWG backend takes only all ten of the SWG091N2's; which ones a file uses is said
// in a comment), ;;Position: Center. No ;;Width: (not a knitout header).
//
// Pure; thread-safe.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>

namespace atelier {

inline constexpr const char* kKnitoutMachine = "SWG091N2";
inline constexpr const char* kKnitoutCarriers = "1 2 3 4 5 6 7 8 9 10";

// Needles per inch of a gauge in stitches per 10 cm, rounded, at least 1.
inline int knitout_gauge(double stitches_per_10cm) {
  return std::max(1, static_cast<int>(std::lround(stitches_per_10cm * 2.54 / 10.0)));
}

// The header lines, each ending in '\n'.
inline std::string knitout_header(double stitches_per_10cm) {
  return std::string(";!knitout-2\n;;Machine: ") + kKnitoutMachine + "\n;;Gauge: " +
         std::to_string(knitout_gauge(stitches_per_10cm)) + "\n;;Carriers: " + kKnitoutCarriers +
         "\n;;Position: Center\n";
}

}  // namespace atelier
