#include "convert/lace/lace_params.h"

#include "convert/common/display_text.h"
#include "convert/common/param_table.h"

namespace atelier {

std::string lace_key_where(const toml::table& table, const std::string& key, const std::string& source) {
  const toml::node* node = table.get(key);
  return (node ? where(*node, source) : display_path(source) + ": ") + "key '" + key + "': ";
}

LaceParams read_lace_params(const toml::table& table, const std::string& source) {
  TableReader r(table, source, "");
  LaceParams p;
  if (r.has("kind")) {
    const std::string kind = r.get_string("kind", "lace");
    if (kind != "lace") r.fail("kind", "this is a lace job; kind must be \"lace\", not \"" + display_value(kind) + "\"");
  }
  p.width = static_cast<int>(r.get_int("width", p.width, 2, 200));
  p.rows = static_cast<int>(r.get_int("rows", p.rows, 1, 200));
  p.population = static_cast<int>(r.get_int("population", p.population, 2, 100000));
  p.generations = static_cast<int>(r.get_int("generations", p.generations, 0, 100000));
  p.holes = r.get_double("holes", p.holes, 0, 1000);
  p.knit_length = r.get_double("knit_length", p.knit_length, 0, 1000);
  p.depth = r.get_double("depth", p.depth, 0, 1000);
  p.symmetry = r.get_double("symmetry", p.symmetry, 0, 1000);
  p.hole_lines = r.get_double("hole_lines", p.hole_lines, 0, 1000);
  p.yo_band = r.get_double("yo_band", p.yo_band, 0, 1000);
  p.width_change = r.get_double("width_change", p.width_change, 0, 1000);
  p.yo_share_min = r.get_double("yo_share_min", p.yo_share_min, 0, 1);
  p.yo_share_max = r.get_double("yo_share_max", p.yo_share_max, 0, 1);
  if (p.yo_share_min > p.yo_share_max) {
    r.fail("yo_share_min", "must not be above yo_share_max (" + std::to_string(p.yo_share_max) + ")");
  }
  // 0 (the default) is no target: a chart that good is no reason to stop.
  if (const double t = r.get_double("target_score", 0, 0, 1e6); t > 0) p.target_score = t;
  p.stagnation = static_cast<int>(r.get_int("stagnation", p.stagnation, 0, 100000));
  p.width_tolerance = static_cast<int>(r.get_int("width_tolerance", p.width_tolerance, 0, 50));
  p.seed = static_cast<std::uint64_t>(r.get_int("seed", 1, 0, int64_t{1} << 53));
  if (r.has("start_chart")) {
    const toml::node& node = *table.get("start_chart");
    p.start_chart_where = lace_key_where(table, "start_chart", source);
    if (const toml::array* rows = node.as_array()) {
      for (const auto& row : *rows) {
        auto text = row.value_exact<std::string>();
        if (!text) r.fail("start_chart", "inline rows must be strings such as \"k1, yo, ssk, k2\"");
        p.start_rows.push_back(*text);
      }
      if (p.start_rows.empty()) r.fail("start_chart", "the inline chart has no rows");
      r.get_array("start_chart");
    } else {
      const std::string file = r.get_string("start_chart", "");
      if (file.empty()) r.fail("start_chart", "expected a chart file (chart.json or instructions.txt) or a list of rows");
      p.start_chart_file = resolve_param_path(file, node);
    }
  }
  p.lace_carriage = r.get_bool("lace_carriage", p.lace_carriage);
  if (p.lace_carriage) p.width_tolerance = 0;
  p.repeats_wide = static_cast<int>(r.get_int("repeats_wide", p.repeats_wide, 1, 50));
  p.repeats_high = static_cast<int>(r.get_int("repeats_high", p.repeats_high, 1, 50));
  r.finish();
  return p;
}

void resolve_lace_config_paths(toml::table& section, const std::filesystem::path& config_dir,
                             const std::filesystem::path& /*state_dir*/) {
  make_path_absolute(section, "start_chart", config_dir);
}

}  // namespace atelier
