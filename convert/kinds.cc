#include "convert/kinds.h"
#include "convert/report_file.h"

#include <algorithm>
#include <fstream>

#include "convert/common/param_table.h"
#include "convert/cut/cut_job.h"
#include "convert/embroidery/embroidery_job.h"
#include "convert/engrave/engrave_job.h"
#include "convert/engrave/engrave_params.h"
#include "convert/embroidery/embroidery_params.h"
#include "convert/knit/knit_job.h"
#include "convert/knit/knit_params.h"
#include "convert/lace/lace_job.h"
#include "convert/lace/lace_params.h"
#include "convert/parquetry/parquetry_job.h"
#include "convert/parquetry/parquetry_params.h"
#include "convert/sketch/sketch_job.h"
#include "convert/sketch/sketch_params.h"

namespace atelier {
namespace {

std::vector<KindInfo> make_kinds() {
  std::vector<KindInfo> k;
  k.push_back({.name = "knit",
               .input = KindInput::image,
               .validate = [](const toml::table& t, const std::string& s) { read_knit_params(t, s); },
               .convert = convert_knit,
               .machine_input = MachineInput::knit_pattern,
               .machine_file = kKnitPatternFile,
               .drivers = {{kAyabDriver, true}},
               .companions = {kRelaxMaskSuffix},
               .previews = {"preview.png", kKnitPatternFile}});
  k.push_back({.name = "cut",
               .input = KindInput::svg,
               .validate = [](const toml::table& t, const std::string& s) { read_cut_params(t, s); },
               .convert = convert_cut,
               .machine_input = MachineInput::gcode,
               .machine_file = kCutGcodeFile,
               .drivers = {{kGrblDriver, true}},
               .previews = {"preview.png"}});
  k.push_back({.name = "parquetry",
               .input = KindInput::image,
               .validate = [](const toml::table& t, const std::string& s) { read_parquetry_params(t, s); },
               .convert = convert_parquetry,
               .resolve_config_paths = resolve_parquetry_config_paths,
               .machine_input = MachineInput::gcode,
               .machine_file = kParquetryGcodeFile,
               .drivers = {{kGrblDriver, true}},
               .previews = {"preview.png", "assembly.svg"},
               .batches = true,
               .uses_wood = true});
  k.push_back({.name = "embroidery",
               .input = KindInput::image,
               .validate = [](const toml::table& t, const std::string& s) { read_embroidery_params(t, s); },
               .convert = convert_embroidery,
               .resolve_config_paths = resolve_embroidery_config_paths,
               .machine_input = MachineInput::stitch_files,
               .machine_file = kDesignStem,
               .formats = stitch_formats(),
               .default_formats = default_stitch_formats(),
               .drivers = {{kFileDropDriver, true}},
               .previews = {"preview.png", "stitches.png", "regions.png"}});
  k.push_back({.name = "lace",
               .input = KindInput::job_file,
               .validate = [](const toml::table& t, const std::string& s) { read_lace_params(t, s); },
               .convert = convert_lace,
               .resolve_config_paths = resolve_lace_config_paths,
               .machine_input = MachineInput::lace_chart,
               .machine_file = kLaceChartFile,
               .drivers = {{kAyabDriver, false}},
               .previews = {"preview.png", "chart.svg"}});
  k.push_back({.name = "sketch",
               .input = KindInput::image,
               .validate = [](const toml::table& t, const std::string& s) { read_sketch_params(t, s); },
               .convert = convert_sketch,
               .resolve_config_paths = resolve_sketch_config_paths,
               .machine_input = MachineInput::gcode,
               .machine_file = kSketchGcodeFile,
               .drivers = {{kGrblDriver, true}},
               .previews = {"preview.png", "lines.svg"}});
  k.push_back({.name = "engrave",
               .input = KindInput::image,
               .validate = [](const toml::table& t, const std::string& s) { read_engrave_params(t, s); },
               .convert = convert_engrave,
               .machine_input = MachineInput::gcode,
               .machine_file = kEngraveGcodeFile,
               .drivers = {{kGrblDriver, true}},
               .previews = {"preview.png"}});
  return k;
}

}  // namespace

const std::vector<KindInfo>& kinds() {
  static const std::vector<KindInfo> table = make_kinds();
  return table;
}

const KindInfo* find_kind(std::string_view name) {
  for (const KindInfo& k : kinds())
    if (k.name == name) return &k;
  return nullptr;
}

const std::vector<std::string>& known_kinds() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const KindInfo& k : kinds()) out.emplace_back(k.name);
    return out;
  }();
  return names;
}

bool is_known_kind(const std::string& kind) { return find_kind(kind) != nullptr; }

std::string known_kinds_text() {
  std::string list;
  for (const auto& k : known_kinds()) list += (list.empty() ? "" : ", ") + k;
  return list;
}

std::string_view report_file_name() { return "report.json"; }  // convert/report_file.h

nlohmann::json read_report(const std::filesystem::path& output_dir) {
  std::ifstream in(output_dir / std::string(report_file_name()));
  return nlohmann::json::parse(in, nullptr, false);
}

bool converts_job_file(const std::string& kind) {
  const KindInfo* k = find_kind(kind);
  return k && k->input == KindInput::job_file;
}

std::vector<std::string> kinds_for_driver(std::string_view driver, bool default_only) {
  std::vector<std::string> out;
  for (const KindInfo& k : kinds())
    for (const DriverUse& d : k.drivers)
      if (d.driver == driver && (d.by_default || !default_only)) out.emplace_back(k.name);
  return out;
}

const std::vector<std::string>& companion_suffixes() {
  static const std::vector<std::string> suffixes = [] {
    std::vector<std::string> out{".toml"};
    for (const KindInfo& k : kinds())
      for (std::string_view c : k.companions)
        if (std::find(out.begin(), out.end(), c) == out.end()) out.emplace_back(c);
    return out;
  }();
  return suffixes;
}

void validate_kind_params(const std::string& kind, const toml::table& params,
                          const std::string& source) {
  const KindInfo* k = find_kind(kind);
  if (!k) throw ParamError(source + ": unknown kind '" + kind + "' (known: " + known_kinds_text() + ")");
  k->validate(params, source);
}

}  // namespace atelier
