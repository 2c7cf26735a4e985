// The name of the report every kind writes beside its outputs (parameters, metrics, timings;
// for laser jobs also "estimated_time_s"). Defined in convert/kinds.cc, the one place outside
// the kind folders where the kinds' file names are spelled (tests/unit/convert/kinds_test.cc).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string_view>

namespace atelier {

std::string_view report_file_name();  // "report.json"

// The report in `output_dir`, parsed; a discarded value (is_discarded()) when it is missing or
// not JSON, so callers read its fields as absent. Reads the file: call it off hot paths.
nlohmann::json read_report(const std::filesystem::path& output_dir);

}  // namespace atelier
