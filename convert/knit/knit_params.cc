#include "convert/knit/knit_params.h"

#include <limits>

#include "convert/common/display_text.h"
#include "convert/common/param_table.h"

namespace atelier {
namespace {

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool parse_rgb(const std::string& text, Rgb& out) {
  if (text.size() != 7 || text[0] != '#') return false;
  uint8_t v[3];
  for (int i = 0; i < 3; ++i) {
    int hi = hex_digit(text[1 + 2 * i]), lo = hex_digit(text[2 + 2 * i]);
    if (hi < 0 || lo < 0) return false;
    v[i] = static_cast<uint8_t>(hi * 16 + lo);
  }
  out = Rgb{v[0], v[1], v[2]};
  return true;
}

}  // namespace

knit::GaugeParams KnitParams::gauge() const {
  knit::GaugeParams g;
  g.width = width;
  g.stitches_per_10cm = stitches_per_10cm;
  g.rows_per_10cm = rows_per_10cm;
  g.orientation = orientation == "vertical" ? knit::Orientation::vertical
                                            : knit::Orientation::horizontal;
  return g;
}

knit::Dither KnitParams::dither_method() const { return knit::dither_from_name(dither); }
knit::Solver KnitParams::solver_kind() const {
  return solver == "auto" ? knit::Solver::hybrid : knit::solver_from_name(solver);
}

KnitParams read_knit_params(const toml::table& table, const std::string& source) {
  TableReader r(table, source, "");
  KnitParams p;
  p.width = static_cast<int>(r.get_int("width", p.width, 8, 1000));
  p.stitches_per_10cm = r.get_double("stitches_per_10cm", p.stitches_per_10cm, 1, 200);
  p.rows_per_10cm = r.get_double("rows_per_10cm", p.rows_per_10cm, 1, 200);
  p.orientation = r.get_choice("orientation", p.orientation, {"horizontal", "vertical"});
  p.dither = r.get_choice("dither", p.dither,
                          {"auto", "threshold", "floyd-steinberg", "atkinson", "ordered"});
  p.threshold = static_cast<int>(r.get_int("threshold", p.threshold, 0, 255));
  p.max_float = static_cast<int>(r.get_int("max_float", p.max_float, 2, 50));
  p.anchoring = r.get_bool("anchoring", p.anchoring);
  p.relax_mask = r.get_string("relax_mask", p.relax_mask);
  p.solver = r.get_choice("solver", p.solver,
                          {"auto", "hybrid", "hybrid-texturing", "gsat", "min-conflict", "random-walk", "texturing",
                           "none"});
  p.seed = static_cast<uint64_t>(
      r.get_int("seed", static_cast<int64_t>(p.seed), 0, std::numeric_limits<int64_t>::max()));
  p.rw_n = static_cast<int>(r.get_int("rw_n", p.rw_n, 1, 100000));
  p.rw_q = static_cast<int>(r.get_int("rw_q", p.rw_q, 0, 100000));
  p.rw_m = static_cast<int>(r.get_int("rw_m", p.rw_m, 1, 100));
  p.invert = r.get_bool("invert", p.invert);
  std::vector<std::string> colors =
      r.get_string_list("colors", {p.colors[0], p.colors[1]});
  if (colors.size() != 2) r.fail("colors", "expected two colours: [background, contrast]");
  for (int i = 0; i < 2; ++i) {
    if (!parse_rgb(colors[i], p.rgb[i])) {
      r.fail("colors", "'" + display_value(colors[i]) + "' is not a colour of the form #rrggbb");
    }
    p.colors[i] = colors[i];
  }
  p.first_row = r.get_choice("first_row", p.first_row, {"bottom", "top"});
  r.finish();
  return p;
}

std::filesystem::path resolve_relax_mask(const KnitParams& params,
                                         const std::filesystem::path& input) {
  namespace fs = std::filesystem;
  if (!params.relax_mask.empty()) {
    fs::path mask(params.relax_mask);
    return mask.is_absolute() ? mask : input.parent_path() / mask;
  }
  fs::path beside = input;
  beside += kRelaxMaskSuffix;
  std::error_code ec;
  if (fs::is_regular_file(beside, ec)) return beside;
  return {};
}

}  // namespace atelier
