#include "convert/engrave/engrave_params.h"

#include "convert/common/param_table.h"

namespace atelier {
namespace {

laser::Dither dither_from_name(const std::string& name) {
  for (laser::Dither d : {laser::Dither::threshold, laser::Dither::ordered, laser::Dither::floyd_steinberg,
                          laser::Dither::jarvis, laser::Dither::stucki, laser::Dither::greyscale})
    if (name == laser::dither_name(d)) return d;
  return laser::Dither::jarvis;  // get_choice admits only the names above
}

}  // namespace

EngraveParams read_engrave_params(const toml::table& params, const std::string& source) {
  TableReader r(params, source, "");
  EngraveParams p;
  p.dither = dither_from_name(r.get_choice(
      "dither", "jarvis", {"threshold", "ordered", "floyd-steinberg", "jarvis", "stucki", "greyscale"}));
  p.dpi = r.get_double("dpi", p.dpi, 10, 1000);
  p.line_interval_mm = r.get_double("line_interval_mm", p.line_interval_mm, 0.01, 5);
  p.spot_mm = r.get_double("spot_mm", p.spot_mm, 0.01, 2);
  p.width_mm = r.get_double("width_mm", p.width_mm, 1, 5000);
  if (const toml::array* pos = r.get_array("position_mm")) {
    auto x = pos->size() == 2 ? pos->get(0)->value<double>() : std::nullopt;
    auto y = pos->size() == 2 ? pos->get(1)->value<double>() : std::nullopt;
    if (!x || !y || !(*x >= 0 && *x <= 5000) || !(*y >= 0 && *y <= 5000))  // NaN fails too
      r.fail("position_mm", "expected [x, y] in mm, each 0..5000");
    p.position_x_mm = *x;
    p.position_y_mm = *y;
  }
  p.speed_mm_min = r.get_double("speed_mm_min", p.speed_mm_min, 1, 100000);
  p.min_power_pct = r.get_double("min_power_pct", p.min_power_pct, 0, 100);
  p.max_power_pct = r.get_double("max_power_pct", p.max_power_pct, 0, 100);
  if (p.min_power_pct > p.max_power_pct)
    r.fail("min_power_pct", "is above max_power_pct (" + laser::format_number(p.max_power_pct) + ")");
  p.gamma = r.get_double("gamma", p.gamma, 0.1, 10);
  p.negative = r.get_bool("negative", p.negative);
  p.threshold = r.get_double("threshold", p.threshold, 0, 1);
  p.bidirectional = r.get_bool("bidirectional", p.bidirectional);
  p.overscan_mm = r.get_double("overscan_mm", p.overscan_mm, 0, 100);
  const toml::table* laser = r.get_table("laser");
  // Not `laser ? *laser : toml::table{}`: that copies, and copies lose their line numbers.
  p.laser = laser ? read_laser_params(*laser, source) : read_laser_params(toml::table{}, source);
  r.finish();
  return p;
}

}  // namespace atelier
