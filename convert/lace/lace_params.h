// Parameters of `lace` jobs, read strictly from the `[lace]` table, a job file or `--set` (an
// unknown key, a wrong type or a value out of range is a ParamError naming the source, line
// and key). Keys (default, range):
//   width = 12 [2, 200]          stitches per pattern repeat (the chart's cast-on and last row)
//   rows = 16 [1, 200]           right-side chart rows (the repeat is twice as many rows: each
//                                is followed by a purled wrong-side row)
//   population = 500 [2, 100000] generations = 200 [0, 100000]
//   holes = 1.0, knit_length = 0.5, depth = 0.2, symmetry = 1.0 [0, 1000]
//                                the weights of the objectives (paper eq. 2; fitness.h)
//   hole_lines = 3.0, yo_band = 50.0, width_change = 0.5 [0, 1000]
//                                more weights of eq. 2: holes in lines (maximised), the distance
//                                of the yarn-over share outside the band and the rows' width
//                                change (both minimised)
//   yo_share_min = 0.10, yo_share_max = 0.25 [0, 1]
//                                the yarn-over share band (fractions of the cells; min <= max)
//   target_score = 0 [0, 1e6]    stop once the best chart scores this much (0: no target)
//   stagnation = 100 [0, 100000]  stop after this many generations without a better chart
//                                (0: run all generations)
//   width_tolerance = 2 [0, 50]  how far an intermediate row may be wider or narrower than the
//                                cast-on, in stitches
//   seed = 1 [0, 2^53]           same seed and parameters, same chart
//   start_chart                  evolve variations of an existing chart: a path to a chart.json
//                                or an instructions.txt (relative to the file that names it),
//                                or the right-side rows inline as written instructions, first
//                                row first: ["k1, yo, ssk, k2", ...]. Its width and rows win.
//   lace_carriage = false        evolve only charts a Brother lace carriage can knit (every row
//                                keeps the width, transfers it can make); forces
//                                width_tolerance = 0
//   repeats_wide = 3 [1, 50], repeats_high = 3 [1, 50]
//                                the swatch: preview, knitout and the knitting machine knit the
//                                chart this many times side by side and on top of itself
//   kind = "lace"                allowed (a job file names its kind); any other value is an error
// Each key is checked on its own here; the conversion also bounds their products (memory,
// time, swatch size: lace_job.h) once all layers are merged.
// Thread-safe (no shared state).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <toml++/toml.h>
#include <vector>

namespace atelier {

struct LaceParams {
  int width = 12;
  int rows = 16;
  int population = 500;
  int generations = 200;
  double holes = 1.0, knit_length = 0.5, depth = 0.2, symmetry = 1.0;
  double hole_lines = 3.0, yo_band = 50.0, width_change = 0.5;
  double yo_share_min = 0.10, yo_share_max = 0.25;
  std::optional<double> target_score;
  int stagnation = 100;
  int width_tolerance = 2;
  std::uint64_t seed = 1;
  std::optional<std::filesystem::path> start_chart_file;  // resolved (absolute or cwd-relative)
  std::vector<std::string> start_rows;                    // inline rows; empty if none
  // "FILE:LINE: key 'start_chart': ", the prefix of every message about the start chart.
  std::string start_chart_where;
  bool lace_carriage = false;
  int repeats_wide = 3;
  int repeats_high = 3;
};

// Throws ParamError naming `source`, the line and the key.
LaceParams read_lace_params(const toml::table& table, const std::string& source);

// "FILE:LINE: key 'KEY': " for a key of `table` (its node names the file it came from), or
// "SOURCE: key 'KEY': " when the key is absent or has no file: the start of a message about a
// key of the merged parameters.
std::string lace_key_where(const toml::table& table, const std::string& key, const std::string& source);


// The [lace] section's `start_chart`, relative to the config file's folder.
void resolve_lace_config_paths(toml::table& section, const std::filesystem::path& config_dir,
                             const std::filesystem::path& state_dir);

}  // namespace atelier
