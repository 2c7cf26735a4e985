#include "convert/common/laser_params.h"

#include <algorithm>
#include <cctype>
#include <map>

#include "convert/common/display_text.h"
#include "convert/common/param_table.h"

namespace atelier {
namespace {

laser::LayerSettings default_layer(const std::string& name, const std::string& color,
                                   laser::Mode mode, double speed, double power) {
  laser::LayerSettings s;
  s.name = name;
  s.color = color;
  s.mode = mode;
  s.speed_mm_min = speed;
  s.power_pct = power;
  return s;
}

laser::LayerSettings read_layer(const toml::table& table, const std::string& source,
                                const std::string& section) {
  TableReader r(table, source, section);
  laser::LayerSettings s;
  if (!r.has("color")) r.fail("color", "missing: every layer needs its stroke colour");
  std::string color = r.get_string("color", "");
  auto parsed = parse_laser_color(color);
  if (!parsed) {
    r.fail("color", "'" + display_value(color) + "' is not a colour (#rrggbb, #rgb or a name such as red)");
  }
  s.color = *parsed;
  s.name = r.get_string("name", color);
  s.mode = r.get_choice("mode", "cut", {"cut", "engrave"}) == "cut" ? laser::Mode::cut
                                                                     : laser::Mode::engrave;
  s.speed_mm_min = r.get_double("speed_mm_min", s.speed_mm_min, 1, 100000);
  s.power_pct = r.get_double("power_pct", s.power_pct, 0, 100);
  s.passes = static_cast<int>(r.get_int("passes", s.passes, 1, 50));
  s.kerf_mm = r.get_double("kerf_mm", s.kerf_mm, 0, 2);
  r.finish();
  return s;
}

}  // namespace

std::optional<std::string> parse_laser_color(const std::string& text) {
  std::string t;
  for (char c : text) t += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  static const std::map<std::string, std::string> names{
      {"black", "#000000"},  {"white", "#ffffff"}, {"red", "#ff0000"},   {"green", "#008000"},
      {"lime", "#00ff00"},   {"blue", "#0000ff"},  {"yellow", "#ffff00"}, {"cyan", "#00ffff"},
      {"magenta", "#ff00ff"}, {"orange", "#ffa500"}, {"gray", "#808080"}, {"grey", "#808080"}};
  if (auto it = names.find(t); it != names.end()) return it->second;
  auto hex = [](const std::string& s) {
    return std::all_of(s.begin() + 1, s.end(), [](char c) { return std::isxdigit(c); });
  };
  if (t.size() == 7 && t[0] == '#' && hex(t)) return t;
  if (t.size() == 4 && t[0] == '#' && hex(t)) {
    return std::string{'#', t[1], t[1], t[2], t[2], t[3], t[3]};
  }
  return std::nullopt;
}

const laser::LayerSettings* layer_for_color(const LaserParams& params, const std::string& color) {
  for (const auto& l : params.layers)
    if (l.color == color) return &l;
  return nullptr;
}

LaserParams read_laser_params(const toml::table& table, const std::string& source) {
  TableReader r(table, source, "laser");
  LaserParams p;
  if (const toml::array* area = r.get_array("work_area_mm")) {
    double v[2] = {0, 0};
    bool ok = area->size() == 2;
    for (size_t i = 0; ok && i < 2; ++i) {
      const toml::node& n = *area->get(i);
      if (auto d = n.value_exact<double>()) v[i] = *d;
      else if (auto k = n.value_exact<int64_t>()) v[i] = static_cast<double>(*k);
      else ok = false;
      ok = ok && v[i] >= 1 && v[i] <= 5000;
    }
    if (!ok) r.fail("work_area_mm", "expected [width, height] in mm, each within 1..5000");
    p.machine.width_mm = v[0];
    p.machine.height_mm = v[1];
  }
  p.machine.s_max = r.get_double("s_max", p.machine.s_max, 1, 100000);
  // Looked up on the table itself, not through the reader: the key is no setting any more (the
  // config test lists the keys readers ask for), only refused with its reason.
  if (const toml::node* origin = table.get("origin")) {
    throw ParamError(where(*origin, source) +
                     "key 'laser.origin': is no longer read: jobs are written in bed "
                     "coordinates (0, 0 = the bed's front-left corner) and the driver places them when a job starts, by its "
                     "start_from = \"bed\" | \"origin\" | \"here\" (sidecar [laser] key or "
                     "`atelierctl start ID --start-from`); remove the key");
  }
  p.machine.travel_mm_min = r.get_double("travel_mm_min", p.machine.travel_mm_min, 1, 100000);
  p.machine.accel_mm_s2 = r.get_double("acceleration_mm_s2", p.machine.accel_mm_s2, 1, 100000);
  p.machine.junction_deviation_mm =
      r.get_double("junction_deviation_mm", p.machine.junction_deviation_mm, 0.001, 1);
  p.tolerance_mm = r.get_double("tolerance_mm", p.tolerance_mm, 0.001, 1);
  p.check_first = r.get_bool("check_first", p.check_first);
  // Read by the driver when the job starts (contract B); checked here so a typo fails early.
  p.start_from = r.get_choice("start_from", p.start_from, {"bed", "origin", "here"});
  if (const toml::array* layers = r.get_array("layer")) {
    for (size_t i = 0; i < layers->size(); ++i) {
      const toml::table* t = layers->get(i)->as_table();
      if (!t) r.fail("layer", "expected [[laser.layer]] tables");
      laser::LayerSettings s = read_layer(*t, source, "laser.layer");
      if (const laser::LayerSettings* twin = layer_for_color(p, s.color)) {
        throw ParamError(where(*t->get("color"), source) + "key 'laser.layer.color': " + s.color +
                         " is already the colour of layer '" + twin->name + "'");
      }
      p.layers.push_back(s);
    }
  }
  if (p.layers.empty()) {
    p.layers = {default_layer("black", "#000000", laser::Mode::cut, 600, 80),
                default_layer("red", "#ff0000", laser::Mode::cut, 600, 80),
                default_layer("blue", "#0000ff", laser::Mode::engrave, 3000, 20)};
  }
  r.finish();
  return p;
}

}  // namespace atelier
