#include "convert/embroidery/embroidery_params.h"

#include "convert/common/display_text.h"
#include "convert/common/param_table.h"

namespace atelier {

EmbroideryParams read_embroidery_params(const toml::table& table, const std::string& source) {
  TableReader r(table, source, "");
  EmbroideryParams p;
  embroidery::DesignParams& d = p.design;
  d.width_mm = r.get_double("width_mm", d.width_mm, 0, 2000);
  if (d.width_mm > 0 && d.width_mm < 5) r.fail("width_mm", "a design is at least 5 mm wide (0 = fit the hoop)");
  if (r.has("colors")) {
    const toml::node& node = *table.get("colors");
    if (auto word = node.value_exact<std::string>()) {
      if (*word != "auto") r.fail("colors", "expected \"auto\" or a number of colours, not \"" + display_value(*word) + "\"");
      r.get_string("colors", "");
      d.colors.colors = 0;
    } else {
      d.colors.colors = static_cast<int>(r.get_int("colors", 0, 1, 64));
    }
  }
  d.colors.max_colors = static_cast<int>(r.get_int("max_colors", d.colors.max_colors, 1, 64));
  if (d.colors.colors > d.colors.max_colors) d.colors.max_colors = d.colors.colors;
  d.colors.median_ksize = static_cast<int>(r.get_int("median", d.colors.median_ksize, 1, 15));
  if (d.colors.median_ksize % 2 == 0) r.fail("median", "the median filter size must be odd");
  d.min_region_mm2 = r.get_double("min_region_mm2", d.min_region_mm2, 0, 10000);
  d.colors.background = r.get_choice("background", "auto", {"auto", "sew"}) == "sew"
                            ? embroidery::Background::sew
                            : embroidery::Background::automatic;
  d.eW_mm = r.get_double("eW", d.eW_mm, 1e-3, 50);
  d.sW_mm = r.get_double("sW", d.sW_mm, 1e-3, 100);
  if (d.sW_mm <= d.eW_mm) r.fail("sW", "the satin width sW must be wider than the edge width eW");
  embroidery::LabelParams& l = d.labels;
  l.k1 = r.get_double("k1", l.k1, 1e-6, 1e6);
  l.k2 = r.get_double("k2", l.k2, 1e-6, 1e6);
  l.k3 = r.get_double("k3", l.k3, 1e-6, 1e6);
  l.k4 = r.get_double("k4", l.k4, 1e-6, 1e6);
  const char* cost_keys[embroidery::kStyleCount] = {"cost_long_short", "cost_satin", "cost_edge"};
  for (int s = 0; s < embroidery::kStyleCount; ++s)
    l.label_cost[s] = r.get_double(cost_keys[s], l.label_cost[s], 0, 1e9);
  d.synthesis.max_L = r.get_double("max_L", d.synthesis.max_L, 0, 100);
  d.overlap_mm = r.get_double("overlap_mm", d.overlap_mm, 0, 5);
  embroidery::StitchParams& s = d.stitches;
  s.fill_row_spacing_mm = r.get_double("fill_row_spacing_mm", s.fill_row_spacing_mm, 0.1, 5);
  s.fill_max_stitch_mm = r.get_double("fill_max_stitch_mm", s.fill_max_stitch_mm, 0.5, 12);
  s.fill_stagger = static_cast<int>(r.get_int("fill_stagger", s.fill_stagger, 1, 16));
  s.fill_underlay = r.get_bool("fill_underlay", s.fill_underlay);
  s.satin_spacing_mm = r.get_double("satin_spacing_mm", s.satin_spacing_mm, 0.1, 5);
  s.satin_pull_comp_mm = r.get_double("satin_pull_comp_mm", s.satin_pull_comp_mm, 0, 2);
  s.satin_max_mm = r.get_double("satin_max_mm", s.satin_max_mm, 1, 12);
  s.satin_underlay = r.get_bool("satin_underlay", s.satin_underlay);
  s.running_stitch_mm = r.get_double("running_stitch_mm", s.running_stitch_mm, 0.5, 12);
  s.edge_satin_min_mm = r.get_double("edge_satin_min_mm", s.edge_satin_min_mm, 0, 10);
  // Moves up to trim_jump_mm are sewn as one stitch: no longer than a DST record may be.
  s.trim_jump_mm = r.get_double("trim_jump_mm", s.trim_jump_mm, 0.5, 12);
  s.min_stitch_mm = r.get_double("min_stitch_mm", s.min_stitch_mm, 0, 0.45);
  s.hoop_width_mm = r.get_double("hoop_width_mm", s.hoop_width_mm, 10, 2000);
  s.hoop_height_mm = r.get_double("hoop_height_mm", s.hoop_height_mm, 10, 2000);
  // A satin span is the column plus pull compensation on both sides: one DST record at most.
  if (s.satin_max_mm + 2 * s.satin_pull_comp_mm > 12)
    r.fail("satin_max_mm", "satin_max_mm + 2 x satin_pull_comp_mm must be at most 12 mm (one "
                           "stitch of a DST file), not " + std::to_string(s.satin_max_mm + 2 * s.satin_pull_comp_mm));
  if (r.has("textures")) {
    const std::string dir = r.get_string("textures", "");
    if (dir.empty()) r.fail("textures", "expected a folder of textures, not an empty string");
    p.textures = resolve_param_path(dir, *table.get("textures"));
  }
  p.texture_dpi = r.get_double("texture_dpi", p.texture_dpi, 50, 4800);
  r.finish();
  return p;
}

void resolve_embroidery_config_paths(toml::table& section, const std::filesystem::path& config_dir,
                                   const std::filesystem::path& /*state_dir*/) {
  make_path_absolute(section, "textures", config_dir);
}

}  // namespace atelier
