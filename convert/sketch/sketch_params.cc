#include "convert/sketch/sketch_params.h"

#include <algorithm>
#include <cctype>

#include "convert/common/display_text.h"
#include "convert/common/param_table.h"
#include "convert/sketch/pencil_profile_file.h"

namespace atelier {
namespace {

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

SketchParams read_sketch_params(const toml::table& params, const std::string& source) {
  TableReader r(params, source, "");
  SketchParams p;
  if (r.has("pencil")) {
    const std::string value = r.get_string("pencil", p.pencil);
    const std::filesystem::path file(value);
    if (file.extension() == ".toml") {
      p.pencil = resolve_param_path(file, *params.get("pencil")).string();
    } else {
      const auto& grades = shipped_pencils();
      auto it = std::find(grades.begin(), grades.end(), upper(value));
      if (it == grades.end()) {
        std::string list;
        for (const auto& g : grades) list += (list.empty() ? "" : ", ") + g;
        r.fail("pencil", "unknown pencil '" + display_value(value) + "' (shipped: " + list +
                             "; or a profile file NAME.toml from `atelier-convert pencil-profile`)");
      }
      p.pencil = *it;
    }
  }
  p.squiggle = r.get_double("squiggle", p.squiggle, 0, 50);
  p.seed = static_cast<std::uint64_t>(r.get_int("seed", 1, 0, int64_t{1} << 53));
  p.scale = r.get_double("scale", p.scale, 0.25, 8);
  p.min_stroke_px = r.get_double("min_stroke_px", p.min_stroke_px, 0, 1000);
  p.smoothing_px = static_cast<int>(r.get_int("smoothing_px", p.smoothing_px, 0, 31));
  p.canny_low = r.get_double("canny_low", p.canny_low, 0, 1000);
  p.canny_high = r.get_double("canny_high", p.canny_high, 0, 1000);
  if (p.canny_high > 0 && p.canny_low > p.canny_high)
    r.fail("canny_low", "must not be above canny_high");
  p.simplify_px = r.get_double("simplify_px", p.simplify_px, 0.1, 50);
  p.max_lines = static_cast<int>(r.get_int("max_lines", p.max_lines, 1, 1000000));
  p.hatching = r.get_bool("hatching", p.hatching);
  p.hatch_level = r.get_double("hatch_level", p.hatch_level, 0, 1);
  p.cross_level = r.get_double("cross_level", p.cross_level, 0, 1);
  p.hatch_spacing_px = r.get_double("hatch_spacing_px", p.hatch_spacing_px, 1, 200);
  p.hatch_angle_deg = r.get_double("hatch_angle_deg", p.hatch_angle_deg, -360, 360);
  p.width_mm = r.get_double("width_mm", p.width_mm, 1, 5000);
  if (const toml::array* pos = r.get_array("position_mm")) {
    auto x = pos->size() == 2 ? pos->get(0)->value<double>() : std::nullopt;
    auto y = pos->size() == 2 ? pos->get(1)->value<double>() : std::nullopt;
    // Written so that NaN fails too (a NaN position hung the laser planner).
    if (!x || !y || !(*x >= 0 && *x <= 5000) || !(*y >= 0 && *y <= 5000))
      r.fail("position_mm", "expected [x, y] in mm, each 0..5000");
    p.position_x_mm = *x;
    p.position_y_mm = *y;
  }
  p.speed_mm_min = r.get_double("speed_mm_min", p.speed_mm_min, 1, 100000);
  p.power_pct = r.get_double("power_pct", p.power_pct, 0, 100);
  const toml::table* laser = r.get_table("laser");
  p.laser = read_laser_params(laser ? *laser : toml::table{}, source);
  r.finish();
  return p;
}

void resolve_sketch_config_paths(toml::table& section, const std::filesystem::path& config_dir,
                               const std::filesystem::path& /*state_dir*/) {
  if (auto pencil = section["pencil"].value_exact<std::string>();
      pencil && std::filesystem::path(*pencil).extension() == ".toml")  // a file, not a grade
    make_path_absolute(section, "pencil", config_dir);
}

}  // namespace atelier
