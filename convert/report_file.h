// The name of the report every kind writes beside its outputs (parameters, metrics, timings;
// for laser jobs also "estimated_time_s"). Defined in convert/kinds.cc, the one place outside
// the kind folders where the kinds' file names are spelled (tests/unit/convert/kinds_test.cc).
#pragma once

#include <string_view>

namespace atelier {

std::string_view report_file_name();  // "report.json"

}  // namespace atelier
