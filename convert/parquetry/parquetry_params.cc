#include "convert/parquetry/parquetry_params.h"

#include <limits>
#include <stdexcept>

#include "convert/common/param_table.h"

namespace atelier {
namespace fs = std::filesystem;

ParquetryParams read_parquetry_params(const toml::table& table, const std::string& source) {
  TableReader r(table, source, "");
  ParquetryParams p;
  parquetry::Params& q = p.plan;
  p.dpi = r.get_double("dpi", p.dpi, 1e-6, 10000);
  q.size_mm = r.get_double("size_mm", q.size_mm, 5, 5000);
  q.patch_mm = r.get_double("patch_mm", q.patch_mm, parquetry::kMinPatchMm, 500);
  q.rotations = static_cast<int>(r.get_int("rotations", q.rotations, 1, 360));
  q.w_intens = r.get_double("w_intens", q.w_intens, 0, 1);
  q.w_edge = r.get_double("w_edge", q.w_edge, 0, 1);
  q.w_hist = r.get_double("w_hist", q.w_hist, 0, 1);
  q.adaptive_levels = static_cast<int>(r.get_int("adaptive_levels", q.adaptive_levels, 0, 4));
  q.adaptive_factor = r.get_double("adaptive_factor", q.adaptive_factor, 0, 100);
  q.order = parquetry::order_from_name(
      r.get_choice("order", parquetry::order_name(q.order), {"saliency", "center"}));
  q.grid = parquetry::grid_from_name(
      r.get_choice("grid", parquetry::grid_name(q.grid), {"regular", "morphed"}));
  q.refine = parquetry::refine_from_name(
      r.get_choice("refine", parquetry::refine_name(q.refine), {"none", "dp"}));
  q.overlap = r.get_double("overlap", q.overlap, 0, 0.5);
  q.kerf_mm = r.get_double("kerf_mm", q.kerf_mm, 0, 2);
  q.min_feature_mm = r.get_double("min_feature_mm", q.min_feature_mm, 0, 50);
  q.seed = static_cast<std::uint64_t>(r.get_int("seed", static_cast<int64_t>(q.seed), 0,
                                                std::numeric_limits<int64_t>::max()));
  q.px_per_mm = r.get_double("px_per_mm", q.px_per_mm, 1e-6, 20);

  if (r.has("wood")) {
    const toml::node& node = *table.get("wood");
    if (auto folder = node.value_exact<std::string>()) {
      if (folder->empty()) r.fail("wood", "expected a folder of scans, not an empty string");
      p.wood_folder = resolve_param_path(*folder, node);
      r.get_string("wood", "");  // mark as read
    } else if (!node.is_array()) {
      r.fail("wood", "expected a folder of scans (a string) or a list of sheets [{id, image}, ...]");
    } else if (const toml::array* list = r.get_array("wood")) {
      if (list->empty()) r.fail("wood", "the list of sheets is empty");
      try {
        p.wood_list = sheets_from_toml(*list, param_base_dir(node), p.dpi, source);
      } catch (const ConvertError& e) {
        throw ParamError(std::string(e.what()) + " (in key 'wood')");
      }
    }
  }
  if (r.has("stock")) {
    const std::string dir = r.get_string("stock", "");
    if (dir.empty()) r.fail("stock", "expected a folder for stock.json, not an empty string");
    p.stock_dir = resolve_param_path(dir, *table.get("stock"));
  }
  if (const toml::table* laser = r.get_table("laser")) {
    p.laser = read_laser_params(*laser, source);
  } else {
    p.laser = read_laser_params(toml::table{}, source);
  }
  r.finish();

  // Cross-checks of the algorithm (e.g. w_intens = w_edge = 0), named by its message.
  try {
    parquetry::validate(q);
  } catch (const std::invalid_argument& e) {
    throw ParamError(source + ": " + e.what());
  }
  return p;
}

std::vector<SheetEntry> require_wood(const ParquetryParams& p, const std::string& source,
                                     const PathAccess& access) {
  if (p.wood_list) {
    // Sheets listed in a job: relative paths from the job's own folder.
    std::vector<SheetEntry> list = *p.wood_list;
    for (SheetEntry& e : list) {
      e.image = access.resolve(e.image);
      if (!e.mask.empty()) e.mask = access.resolve(e.mask);
    }
    return list;
  }
  if (p.wood_folder) return list_sheets(access, *p.wood_folder, p.dpi);
  throw ParamError(source + ": parquetry needs `wood`: a folder of veneer scans "
                   "(wood = \"/var/lib/atelier/wood\") or a list of sheets "
                   "(wood = [{id = \"maple\", image = \"maple.png\", dpi = 300}]), in [parquetry], "
                   "a sidecar or --set wood=FOLDER");
}

void resolve_parquetry_config_paths(toml::table& section, const std::filesystem::path& config_dir,
                                  const std::filesystem::path& state_dir) {
  if (!section.contains("wood")) section.insert("wood", (state_dir / "wood").string());
  if (!section.contains("stock")) section.insert("stock", (state_dir / "wood-stock").string());
  make_path_absolute(section, "wood", config_dir);
  make_path_absolute(section, "stock", config_dir);
  if (toml::array* list = section["wood"].as_array())
    for (auto& sheet : *list)
      if (toml::table* s = sheet.as_table()) {
        make_path_absolute(*s, "image", config_dir);
        make_path_absolute(*s, "mask", config_dir);
      }
}

}  // namespace atelier
