// Parameters of `embroidery` jobs, read strictly from the `[embroidery]` table, a sidecar or
// `--set` (an unknown key, a wrong type or a value out of range is a ParamError naming the
// source, line and key).
//
// Keys (default, range); lengths in mm of the sewn design:
//   width_mm = 0: fit, or [5, 2000]    the design's width; its height follows the image;
//                                      0 = as large as fits the hoop, 5 mm in from its edge
//   colors = "auto" | 1..64            thread colours (paper 4: CIELab clustering)
//   max_colors = 12 [1, 64]            cap for "auto"
//   median = 3 [1, 15], odd            median filter before clustering (5 erases 2-px lines)
//   min_region_mm2 = 1 [0, 10000]      smaller single-colour specks join a neighbour
//   background = "auto" | "sew"        auto: transparent pixels and a white border colour are
//                                      the fabric (not sewn); sew: every opaque pixel is sewn
//   eW = 1.0 (0, 50]  sW = 6.0 (0, 100]   the paper's edge and satin widths, in mm; sW > eW
//   k1, k2, k3, k4 (0, 1e6]            the paper's cost weights (eq. 1-5); defaults: LabelParams
//   cost_long_short, cost_satin, cost_edge [0, 1e9]   label costs (eq. 6)
//   max_L = 85 [0, 100]                recolouring caps thread lightness (paper 5.4)
//   overlap_mm = 0.25 [0, 5]           regions are dilated this much (paper 5.5)
//   fill_row_spacing_mm = 0.25 [0.1, 5]   fill_max_stitch_mm = 3 [0.5, 12]
//   fill_stagger = 4 [1, 16]           fill_underlay = true
//   satin_spacing_mm = 0.4 [0.1, 5]    satin_pull_comp_mm = 0.2 [0, 2]
//   satin_max_mm = 8 [1, 12]           satin_underlay = true
//                                      (satin_max_mm + 2 x satin_pull_comp_mm <= 12: one stitch)
//   running_stitch_mm = 1.5 [0.5, 12]  edge_satin_min_mm = 1 [0, 10]
//   trim_jump_mm = 3 [0.5, 12]         longer moves with no hidden way are jumps with a trim
//   min_stitch_mm = 0.1 [0, 0.45]      stitches this short or shorter are dropped
//   hoop_width_mm = 100, hoop_height_mm = 100 [10, 2000]   the machine's sewing field
//   textures = FOLDER                  user reference textures (see embroidery_job.h);
//                                      absent = the procedural ones
//   texture_dpi = 600 [50, 4800]       resolution of the user textures (sets stitch length)
//
// Thread-safe (no shared state).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <toml++/toml.h>

#include "algorithms/embroidery/pipeline.h"

namespace atelier {

struct EmbroideryParams {
  embroidery::DesignParams design;
  std::optional<std::filesystem::path> textures;  // resolved against its file's folder
  double texture_dpi = 600;
};

// Throws ParamError.
EmbroideryParams read_embroidery_params(const toml::table& params, const std::string& source);


// The [embroidery] section's `textures` folder, relative to the config file's folder.
void resolve_embroidery_config_paths(toml::table& section, const std::filesystem::path& config_dir,
                                   const std::filesystem::path& state_dir);

}  // namespace atelier
