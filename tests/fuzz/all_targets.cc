#include "tests/fuzz/fuzz_targets.h"

namespace atelier::fuzz {

const std::vector<TargetInfo>& all_targets() {
  static const std::vector<TargetInfo> targets = {
      {"svg_reader", fuzz_svg_reader},
      {"param_table", fuzz_param_table},
      {"lace_job", fuzz_lace_job},
      {"lace_chart_json", fuzz_lace_chart_json},
      {"pencil_profile", fuzz_pencil_profile},
      {"ayab_messages", fuzz_ayab_messages},
      {"grbl_replies", fuzz_grbl_replies},
      {"control_request", fuzz_control_request},
      {"knit_emu_firmware", fuzz_knit_emu_firmware},
      {"laser_emu_gcode", fuzz_laser_emu_gcode},
      {"image_header", fuzz_image_header},
  };
  return targets;
}

}  // namespace atelier::fuzz
