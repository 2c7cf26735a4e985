// chart.json of a lace job: {"rows": [["k", "yo", "ssk", ...], ...]}, rows[0] the first row
// knitted, each row in knitting order (right to left as a knitter reads the chart), wrong-side
// (purl) rows omitted; plus "cast_on", the stitches the chart is worked over (its repeat
// width), and "repeats_wide" / "repeats_high", the swatch the job knits (preview, knitout and
// the machine: the chart repeated side by side and on top of itself). Read by the
// knitting-machine device and by `start_chart`.
// Written too (issue 22), never read back: "layout", the chart as printed (chart_layout.h):
// {"columns": W, "rows": [[cell, ...], ...]}, rows as in "rows", each W cells in knitting order
// (column 0 the chart's right edge), a cell the symbol's name or null for a "no stitch" cell.
// Readers that know only "rows" are unaffected; files without "layout" read as before.
// Pure; thread-safe.
#pragma once

#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "algorithms/lace/chart.h"

namespace atelier {

struct LaceChartFile {
  lace::Chart chart;
  int cast_on = 0;
  int repeats_wide = 1;  // >= 1
  int repeats_high = 1;  // >= 1
};

nlohmann::json lace_chart_to_json(const LaceChartFile& file);

// Throws std::invalid_argument naming `source` and the problem (not an object, a row that
// is not a list of symbol names, an unknown symbol, a chart that cannot be knitted from its
// cast-on, cast_on outside 1..kMaxLaceChartCastOn, repeats outside 1..kMaxLaceChartRepeats as
// a lace job's parameters allow). A missing "cast_on" is taken as what row 0 is worked over;
// missing repeats are 1.
inline constexpr int kMaxLaceChartCastOn = 10000;
inline constexpr int kMaxLaceChartRepeats = 50;
LaceChartFile lace_chart_from_json(const nlohmann::json& j, const std::string& source);
// The same from the file's text: text that is not JSON is std::invalid_argument too ("not
// JSON: ..."), naming `source` like the rest.
LaceChartFile lace_chart_from_json_text(const std::string& text, const std::string& source);

}  // namespace atelier
