#include "convert/common/job_start.h"

#include <cctype>

#include "convert/common/param_table.h"

namespace atelier {

std::optional<int> parse_bed_needle(const std::string& text, int needles, std::string* problem) {
  const int half = needles / 2;
  auto fail = [&]() -> std::optional<int> {
    if (problem)
      *problem = "needles are named by the bed's markings L" + std::to_string(half) + "..L1, R1..R" +
                 std::to_string(half) + " or counted from the left end, 1.." + std::to_string(needles);
    return std::nullopt;
  };
  if (text.empty() || text.size() > 4) return fail();
  size_t digits_from = 0;
  const char side = static_cast<char>(std::toupper(static_cast<unsigned char>(text[0])));
  if (side == 'L' || side == 'R') digits_from = 1;
  if (digits_from == text.size()) return fail();
  int n = 0;
  for (size_t i = digits_from; i < text.size(); ++i) {
    if (!std::isdigit(static_cast<unsigned char>(text[i]))) return fail();
    n = n * 10 + (text[i] - '0');
  }
  if (digits_from == 0) {
    if (n < 1 || n > needles) return fail();
    return n - 1;
  }
  if (n < 1 || n > half) return fail();
  return side == 'L' ? half - n : half + n - 1;
}

std::string bed_needle_name(int index, int needles) {
  const int half = needles / 2;
  return index < half ? "L" + std::to_string(half - index) : "R" + std::to_string(index - half + 1);
}

JobStart take_job_start(toml::table& layer, const std::string& source) {
  JobStart out;
  auto bad = [&](const char* key, const std::string& problem) {
    throw ParamError(where(*layer.get(key), source) + "key '" + key + "': " + problem);
  };
  if (const toml::node* n = layer.get("autostart")) {
    if (!n->is_boolean()) bad("autostart", "expected true or false");
    out.autostart = n->value<bool>();
  }
  if (const toml::node* n = layer.get("start_row")) {
    const auto v = n->value<int64_t>();
    if (!n->is_integer() || !v) bad("start_row", "expected a row number (1 is the first row knitted)");
    if (*v < 1 || *v > 1000000) bad("start_row", "rows are counted from 1 (the first row knitted)");
    out.start_row = static_cast<int>(*v);
  }
  if (const toml::node* n = layer.get("start_needle")) {
    std::string text;
    if (n->is_integer()) text = std::to_string(*n->value<int64_t>());
    else if (n->is_string()) text = *n->value<std::string>();
    else bad("start_needle", "expected a needle such as \"L20\", \"R5\" or 30");
    std::string problem;
    if (!parse_bed_needle(text, 200, &problem)) bad("start_needle", "'" + text + "' is no needle: " + problem);
    out.start_needle = text;
  }
  layer.erase("autostart");
  layer.erase("start_row");
  layer.erase("start_needle");
  return out;
}

LaserJobStart take_laser_job_start(toml::table& layer, const std::string& source) {
  LaserJobStart out;
  toml::table* laser = layer["laser"].as_table();
  if (!laser) return out;
  auto bad = [&](const char* key, const std::string& problem) {
    throw ParamError(where(*laser->get(key), source) + "key 'laser." + key + "': " + problem);
  };
  if (const toml::node* n = laser->get("check_first")) {
    if (!n->is_boolean()) bad("check_first", "expected true or false");
    out.check_first = n->value<bool>();
  }
  if (const toml::node* n = laser->get("start_from")) {
    const auto v = n->value_exact<std::string>();
    if (!v || (*v != "bed" && *v != "origin" && *v != "here"))
      bad("start_from", "expected \"bed\" (the bed's front-left corner), \"origin\" (the work zero set "
                        "with `atelierctl laser origin`) or \"here\" (the head's position at start)");
    out.start_from = *v;
  }
  laser->erase("check_first");
  laser->erase("start_from");
  return out;
}

}  // namespace atelier
