#include "convert/lace/lace_chart_json.h"

#include "algorithms/lace/chart_layout.h"

namespace atelier {

nlohmann::json lace_chart_to_json(const LaceChartFile& file) {
  nlohmann::json rows = nlohmann::json::array();
  for (const lace::Row& row : file.chart.rows) {
    nlohmann::json r = nlohmann::json::array();
    for (lace::Symbol s : row) r.push_back(std::string(lace::name(s)));
    rows.push_back(std::move(r));
  }
  nlohmann::json out = {{"cast_on", file.cast_on},
                        {"repeats_wide", file.repeats_wide},
                        {"repeats_high", file.repeats_high},
                        {"rows", std::move(rows)}};
  // The printed layout, only for a chart it can be made of (the reader refuses other charts).
  if (lace::knittable(file.chart, file.cast_on)) {
    const lace::ChartLayout layout = lace::layout_chart(file.chart, file.cast_on);
    nlohmann::json grid = nlohmann::json::array();
    for (std::size_t r = 0; r < layout.cells.size(); ++r) {
      nlohmann::json cells = nlohmann::json::array();
      for (int j : layout.cells[r]) {
        if (j < 0) cells.push_back(nullptr);
        else cells.push_back(std::string(lace::name(file.chart.rows[r][static_cast<std::size_t>(j)])));
      }
      grid.push_back(std::move(cells));
    }
    out["layout"] = {{"columns", layout.columns}, {"rows", std::move(grid)}};
  }
  return out;
}

LaceChartFile lace_chart_from_json(const nlohmann::json& j, const std::string& source) {
  auto fail = [&](const std::string& why) -> void {
    throw std::invalid_argument(source + ": " + why);
  };
  if (!j.is_object() || !j.contains("rows") || !j["rows"].is_array())
    fail("not a lace chart: expected {\"rows\": [[\"k\", \"yo\", ...], ...]}");
  LaceChartFile out;
  const auto& rows = j["rows"];
  for (size_t r = 0; r < rows.size(); ++r) {
    if (!rows[r].is_array()) fail("row " + std::to_string(r + 1) + " is not a list of symbols");
    lace::Row row;
    for (const auto& cell : rows[r]) {
      if (!cell.is_string()) fail("row " + std::to_string(r + 1) + ": a symbol must be a string");
      try {
        row.push_back(lace::parse_symbol(cell.get<std::string>()));
      } catch (const std::invalid_argument& e) {
        fail("row " + std::to_string(r + 1) + ": " + e.what());
      }
    }
    out.chart.rows.push_back(std::move(row));
  }
  if (out.chart.rows.empty()) fail("the chart has no rows");
  // Compared as 64-bit numbers: get<int>() would wrap 4294967308 round to 12.
  auto whole = [&](const char* key, long long lo, long long hi) {
    return j[key].is_number_integer() && j[key].get<long long>() >= lo && j[key].get<long long>() <= hi;
  };
  if (j.contains("cast_on")) {
    if (!whole("cast_on", 1, kMaxLaceChartCastOn))
      fail("cast_on must be a whole number of stitches, 1 to " + std::to_string(kMaxLaceChartCastOn));
    out.cast_on = j["cast_on"].get<int>();
  } else {
    out.cast_on = lace::consumed(out.chart.rows[0]);
  }
  for (auto [key, field] : {std::pair{"repeats_wide", &out.repeats_wide}, {"repeats_high", &out.repeats_high}}) {
    if (!j.contains(key)) continue;
    if (!whole(key, 1, kMaxLaceChartRepeats))
      fail(std::string(key) + " must be a whole number of repeats, 1 to " + std::to_string(kMaxLaceChartRepeats));
    *field = j[key].get<int>();
  }
  const lace::Knittability k = lace::knittable(out.chart, out.cast_on);
  if (!k) fail(k.why);
  return out;
}

LaceChartFile lace_chart_from_json_text(const std::string& text, const std::string& source) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    // Where, never what: nlohmann's message quotes the bytes it read ("last read: '...'").
    size_t line = 1, column = 1;
    for (size_t i = 0; i + 1 < e.byte && i < text.size(); ++i) {
      if (text[i] == '\n') ++line, column = 1;
      else ++column;
    }
    throw std::invalid_argument(source + ": not JSON: syntax error at line " + std::to_string(line) +
                                ", column " + std::to_string(column));
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(source + ": not JSON (error " + std::to_string(e.id) + ")");
  }
  return lace_chart_from_json(j, source);
}

}  // namespace atelier
