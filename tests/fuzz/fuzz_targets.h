// The fuzz targets: each takes one input (bytes owned by the caller, any content) through a
// real parsing entry point of atelier and returns 0. A target never throws: the errors a parser
// reports for bad input (ParamError, ConvertError, std::invalid_argument, ...) are its normal
// answer. A crash, a sanitizer report or an uncaught exception is a finding.
//
// Built two ways: with ATELIER_FUZZ=ON (clang) each target is an executable fuzz_<name> whose
// LLVMFuzzerTestOneInput calls fuzz_<name> (libfuzzer_entry.cc); in the normal test binary
// tests/unit/fuzz/corpus_replay_test.cc replays tests/fuzz/corpus/<name>/ and
// tests/fuzz/regressions/<name>/ through them.
//
// Inputs longer than kMaxFuzzInput bytes are ignored, so that every execution stays fast.
// Threading: a target may be called from one thread at a time (some use a memfd and the
// process's file table, none keeps state between calls).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

namespace atelier::fuzz {

inline constexpr size_t kMaxFuzzInput = 64 * 1024;  // bytes

using Target = int (*)(const uint8_t* data, size_t size);
struct TargetInfo {
  std::string_view name;  // folder name under corpus/ and regressions/
  Target run;
};
// Every target, in a fixed order.
const std::vector<TargetInfo>& all_targets();

}  // namespace atelier::fuzz

// The SVG reader (convert/common/svg_paths: read_svg).
int fuzz_svg_reader(const uint8_t* data, size_t size);
// Parameter tables: the daemon config (parse_config), a sidecar validated as each kind's
// parameters, and each line as a `--set key=value` (convert/common/param_table, the kinds).
int fuzz_param_table(const uint8_t* data, size_t size);
// A lace job file: read_lace_params, inline start charts, the budget and feasibility checks.
int fuzz_lace_job(const uint8_t* data, size_t size);
// A lace chart.json (convert/lace/lace_chart_json: lace_chart_from_json_text).
int fuzz_lace_chart_json(const uint8_t* data, size_t size);
// A pencil profile (convert/sketch/pencil_profile_file: profile_from_toml).
int fuzz_pencil_profile(const uint8_t* data, size_t size);
// Bytes from a knitting machine: AYAB SLIP framing and message decoding (drivers/ayab).
int fuzz_ayab_messages(const uint8_t* data, size_t size);
// Lines from a GRBL controller (drivers/grbl/messages).
int fuzz_grbl_replies(const uint8_t* data, size_t size);
// One control-socket request line (daemon/control_request: parse_request).
int fuzz_control_request(const uint8_t* data, size_t size);
// Bytes from the host into the knitting-machine emulator's firmware (tools/knit_emu).
int fuzz_knit_emu_firmware(const uint8_t* data, size_t size);
// G-code lines into the laser emulator: its parser and its controller (tools/laser_emu).
int fuzz_laser_emu_gcode(const uint8_t* data, size_t size);
// Image headers and completeness checks (convert/common/image_signature).
int fuzz_image_header(const uint8_t* data, size_t size);
