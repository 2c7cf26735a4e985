#include "daemon/job_sets.h"

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

namespace atelier {
namespace {

std::string trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") + 1 - b);
}

// A bare or quoted TOML key as written by toml++ ("a.b" for a key that holds a dot); `rest`
// gets what follows it.
std::string read_key(const std::string& text, std::string& rest) {
  std::string key;
  size_t i = 0;
  if (!text.empty() && (text[0] == '"' || text[0] == '\'')) {
    const char quote = text[0];
    for (i = 1; i < text.size() && text[i] != quote; ++i) {
      if (quote == '"' && text[i] == '\\' && i + 1 < text.size()) ++i;
      key += text[i];
    }
    ++i;
  } else {
    while (i < text.size() && text[i] != '=' && text[i] != ' ' && text[i] != '\t' && text[i] != ']') key += text[i++];
  }
  rest = i < text.size() ? text.substr(i) : "";
  return key;
}

// Brackets and braces still open at the end of `text`, outside strings.
int open_brackets(const std::string& text) {
  int depth = 0;
  char quote = 0;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quote) {
      if (quote == '"' && c == '\\') ++i;
      else if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '#') {
      break;
    } else if (c == '[' || c == '{') {
      ++depth;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return depth;
}

// One level of sections: [name] or [a.b] headers and the "k = v" lines under them.
struct Section {
  std::vector<std::pair<std::string, std::string>> entries;  // key, value text
  std::map<std::string, Section> children;
  std::vector<std::string> order;  // children in the order they appeared
};

std::string inline_table(const Section& s) {
  std::string out = "{";
  bool first = true;
  for (const auto& [k, v] : s.entries) {
    out += (first ? "" : ", ") + nlohmann::json(k).dump() + " = " + v;
    first = false;
  }
  for (const auto& name : s.order) {
    out += (first ? "" : ", ") + nlohmann::json(name).dump() + " = " + inline_table(s.children.at(name));
    first = false;
  }
  return out + "}";
}

std::vector<std::string> legacy_sets(const std::string& text) {
  Section root;
  Section* current = &root;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    line = trim(line);
    if (line.empty() || line[0] == '#') continue;
    if (line[0] == '[') {
      if (line.size() > 1 && line[1] == '[') continue;  // arrays of tables: never written by --set
      current = &root;
      std::string rest = line.substr(1);
      for (;;) {
        rest = trim(rest);
        const std::string part = read_key(rest, rest);
        if (part.empty()) break;
        if (!current->children.count(part)) current->order.push_back(part);
        current = &current->children[part];
        rest = trim(rest);
        if (rest.empty() || rest[0] != '.') break;
        rest = rest.substr(1);
      }
      continue;
    }
    std::string rest;
    const std::string key = read_key(line, rest);
    rest = trim(rest);
    if (key.empty() || rest.empty() || rest[0] != '=') continue;
    std::string value = trim(rest.substr(1));
    // An array or inline table printed over several lines: join them.
    std::string more;
    while (open_brackets(value) > 0 && std::getline(in, more)) value += " " + trim(more);
    current->entries.emplace_back(key, value);
  }
  std::vector<std::string> sets;
  for (const auto& [k, v] : root.entries) sets.push_back(k + "=" + v);
  for (const auto& name : root.order) sets.push_back(name + "=" + inline_table(root.children.at(name)));
  return sets;
}

}  // namespace

std::string sets_to_params(const std::vector<std::string>& sets) {
  if (sets.empty()) return "";
  return nlohmann::json(sets).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::vector<std::string> params_to_sets(const std::string& params) {
  if (trim(params).empty()) return {};
  if (trim(params)[0] == '[') {
    const nlohmann::json j = nlohmann::json::parse(params, nullptr, /*allow_exceptions=*/false);
    if (j.is_array() && std::all_of(j.begin(), j.end(), [](const auto& e) { return e.is_string(); }))
      return j.get<std::vector<std::string>>();
  }
  return legacy_sets(params);  // a store from before: TOML text, read line by line
}

}  // namespace atelier
