// Parameters of `parquetry` jobs, read strictly from the `[parquetry]` table, a sidecar or
// `--set` (like laser_params / knit_params: an unknown key, a wrong type or a value out of
// range is a ParamError naming the source, line and key).
//
// Keys (default, range); defaults are parquetry::Params' (algorithms/parquetry/params.h):
//   wood            required for a conversion: a folder of scans (string; see wood_library.h)
//                   or a list of sheets [{id, image, mask?, dpi?}, ...]. A relative folder or
//                   image path is relative to the folder of the file that set it, else the cwd.
//   dpi = 300 (0..10000]   resolution of scans that do not state their own
//   size_mm = 360 [5, 5000]      patch_mm = 14 [5, 500]     rotations = 15 [1, 360]
//   w_intens = 0.5, w_edge = 0.5, w_hist = 0.5 [0, 1]
//   adaptive_levels = 0 [0, 4]   adaptive_factor = 1.2 [0, 100]
//   order = "saliency" | "center"   grid = "regular" | "morphed"   refine = "none" | "dp"
//   overlap = 0.3 [0, 0.5]   kerf_mm = 0.2 [0, 2]   min_feature_mm = 2 [0, 50]
//   seed = 0 [0, 2^63)       px_per_mm = 0.5 (0, 20]
//   stock           folder of stock.json (string); absent = plan on all wood, persist nothing
//   laser           the [laser] table (laser_params.h), injected by the daemon as for `cut`
//
// Thread-safe (no shared state).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <toml++/toml.h>
#include <vector>

#include "algorithms/parquetry/params.h"
#include "convert/common/laser_params.h"
#include "inventory/wood_library.h"

namespace atelier {

struct ParquetryParams {
  parquetry::Params plan;
  // The wood, as given: a folder (wood_folder) or a list (wood_list); neither if absent.
  std::optional<std::filesystem::path> wood_folder;  // resolved against its file's folder
  std::optional<std::vector<SheetEntry>> wood_list;
  double dpi = 300;
  std::optional<std::filesystem::path> stock_dir;
  LaserParams laser;
};

// Reads and checks one table (a config section, sidecar, --set layer or the merged whole).
// `wood` may be absent here (it may come from another layer); see require_wood().
// Throws ParamError.
ParquetryParams read_parquetry_params(const toml::table& params, const std::string& source);

// The sheets to plan on: the listed ones, or the folder's (wood_library.h list_sheets).
// Throws ParamError "parquetry needs `wood` ..." when neither was given, ConvertError for a
// folder that cannot be read.
// `access`: how the folder and the scans are opened (confined when a job named them).
std::vector<SheetEntry> require_wood(const ParquetryParams& params, const std::string& source,
                                     const PathAccess& access = PathAccess());


// The [parquetry] section's wood library and stock: under state_dir (wood/, wood-stock/)
// unless given; `wood`, `stock` and each inline sheet's image and mask relative to config_dir.
void resolve_parquetry_config_paths(toml::table& section, const std::filesystem::path& config_dir,
                                  const std::filesystem::path& state_dir);

}  // namespace atelier
