// Parameters of a `knit` job, read strictly from a TOML table (the [knit] config section,
// a sidecar, `--set` overrides, or their merge).
//
// Keys (default, range):
//   width = 120 (8..1000)            stitches per row
//   stitches_per_10cm = 28, rows_per_10cm = 36 (1..200)   gauge; keeps the picture's aspect
//   orientation = "horizontal" | "vertical"  (vertical: knitted sideways)
//   dither = "auto" | "threshold" | "floyd-steinberg" | "atkinson" | "ordered"
//                                    auto: chosen by measurement (auto_choice.h): every
//                                    dither is solved and the best blurred SSIM at zero
//                                    violations wins; report.json lists what was tried
//   threshold = 128 (0..255)         grey level between the two colours
//   max_float = 4 (2..50)            longest allowed run of one colour
//   anchoring = true                 both yarns anchored at the row edges
//   relax_mask = ""                  image whose dark (< 128, alpha on white) areas are relaxed
//                                    (floats allowed); a relative path is resolved against
//                                    the folder of the input image. When empty and a file
//                                    `<input>.relax.png` exists beside the input (e.g.
//                                    `cat.jpg.relax.png`), that file is used.
//   solver = "auto" | "hybrid" | "hybrid-texturing" | "gsat" | "min-conflict" | "random-walk" |
//            "texturing" | "none"   (hybrid: Random Walk + GSAT; hybrid-texturing: Random
//            Walk + pseudo-random texturing, the paper's second hybrid; auto: the complete
//            solvers hybrid, hybrid-texturing, gsat, texturing are tried with the dither(s)
//            and measured as for dither = "auto")
//   seed = 1, rw_n = 100 (1..100000), rw_q = 5 (0..100000), rw_m = 4 (1..100)
//   invert = false                   false: dark areas get the contrast colour
//   colors = ["#f4efe6", "#3a2a5c"]  background, contrast yarn as #rrggbb (preview, chart)
//   first_row = "bottom" | "top"     the picture row knitted first (row 1 of chart.pdf and
//                                    pattern.k; the machine follows report.json's first_row).
//                                    bottom: the cast-on edge is the picture's bottom, so the
//                                    fabric is the picture upright (as AYAB desktop knits);
//                                    top: knitted top-down, the fabric comes off upside down.
//
// Unknown keys, wrong types and values out of range are ParamError "FILE:LINE: key 'k': ...".
// Thread-safe (no shared state).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <toml++/toml.h>

#include "algorithms/knit/dither.h"
#include "algorithms/knit/solvers.h"
#include "algorithms/knit/stitch_grid.h"

namespace atelier {

struct Rgb {
  uint8_t r = 0, g = 0, b = 0;
};

struct KnitParams {
  int width = 120;
  double stitches_per_10cm = 28;
  double rows_per_10cm = 36;
  std::string orientation = "horizontal";
  std::string dither = "auto";
  int threshold = 128;
  int max_float = 4;
  bool anchoring = true;
  std::string relax_mask;  // as given ("" = none)
  std::string solver = "auto";
  uint64_t seed = 1;
  int rw_n = 100;
  int rw_q = 5;
  int rw_m = 4;
  bool invert = false;
  std::array<std::string, 2> colors{"#f4efe6", "#3a2a5c"};  // background, contrast
  std::array<Rgb, 2> rgb{};  // `colors` parsed
  std::string first_row = "bottom";  // "bottom" | "top": the picture row knitted first

  knit::GaugeParams gauge() const;
  knit::Dither dither_method() const;
  bool solver_auto() const { return solver == "auto"; }
  knit::Solver solver_kind() const;  // hybrid for "auto" (auto is resolved by measurement)
};

// Reads every key of `table` (see above); `source` names the file for errors without line.
KnitParams read_knit_params(const toml::table& table, const std::string& source);

// The relax mask dropped beside an image: NAME.EXT + this suffix.
inline constexpr const char* kRelaxMaskSuffix = ".relax.png";

// The relax mask to use for `input`: `relax_mask` resolved against the input's folder, or
// the `<input>.relax.png` beside it, or an empty path when there is none.
std::filesystem::path resolve_relax_mask(const KnitParams& params,
                                         const std::filesystem::path& input);

}  // namespace atelier
