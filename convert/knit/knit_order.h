// The row order of a knit job, read back from its report.json by the knitting machine's
// device, so the machine knits the rows in the order chart.pdf and pattern.k were made for.
//
// The order is a conversion parameter ([knit] first_row, knit_params.h) because the chart and
// the knitout are drawn for it; convert_knit records it as report.json's "first_row".
// Pure file reading; thread-safe.
#pragma once

#include <filesystem>

namespace atelier {

// True when the job in `output_dir` knits pattern.png's top row (row 0) first; false when it
// knits the bottom row first (the default). A folder with no report, or a report without
// "first_row", knits bottom first (the default since reports have recorded it). Throws
// BadInput naming the report when it cannot be read or parsed, or names another order.
bool job_knits_top_row_first(const std::filesystem::path& output_dir);

}  // namespace atelier
