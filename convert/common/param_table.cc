#include "convert/common/param_table.h"

#include <cmath>
#include <type_traits>
#include <sstream>

#include "convert/common/display_text.h"

namespace atelier {

std::string where(const toml::node& node, const std::string& fallback_source) {
  const auto& src = node.source();
  std::string file = display_path(src.path ? *src.path : fallback_source);
  if (src.begin.line > 0) return file + ":" + std::to_string(src.begin.line) + ": ";
  return file + ": ";
}

std::string toml_error_text(const toml::parse_error& error, const std::string& source) {
  std::string d(error.description());
  // "expected '=', saw 'x'": what was seen is the file's content.
  for (const char* cut : {", saw", " saw "})
    if (size_t at = d.find(cut); at != std::string::npos) d.erase(at);
  // Quoted parts longer than a token ("cannot redefine existing table 'a.b'") name content.
  std::string out;
  for (size_t i = 0; i < d.size();) {
    const size_t close = d[i] == '\'' ? d.find('\'', i + 1) : std::string::npos;
    if (close == std::string::npos) {
      out += d[i++];
      continue;
    }
    const std::string inner = d.substr(i + 1, close - i - 1);
    out += "'" + (inner.size() <= 2 ? inner : std::string("...")) + "'";
    i = close + 1;
  }
  while (!out.empty() && (out.back() == ' ' || out.back() == ',' || out.back() == ':')) out.pop_back();
  const auto& begin = error.source().begin;
  std::string at = display_path(source);
  if (begin.line > 0) at += ":" + std::to_string(begin.line) + ":" + std::to_string(begin.column);
  return at + ": not valid TOML: " + safe_text(out);
}

namespace {
thread_local ParamKeyLog* current_key_log = nullptr;
}  // namespace

ParamKeyLog::ParamKeyLog() : previous_(current_key_log) { current_key_log = this; }
ParamKeyLog::~ParamKeyLog() { current_key_log = previous_; }

template <typename T>
void TableReader::note_default(const std::string& key, const T& def) const {
  if (!current_key_log) return;
  ParamKeyUse use{&table_, key, {}};
  if constexpr (std::is_same_v<T, std::vector<std::string>>) {
    toml::array a;
    for (const auto& s : def) a.push_back(s);
    use.default_value.insert("v", std::move(a));
  } else {
    use.default_value.insert("v", def);
  }
  current_key_log->add(std::move(use));
}

TableReader::TableReader(const toml::table& table, std::string source, std::string section)
    : table_(table), source_(std::move(source)), section_(std::move(section)) {}

const toml::node* TableReader::node(const std::string& key) {
  read_.insert(key);
  if (current_key_log) current_key_log->add({&table_, key, {}});
  return table_.get(key);
}

bool TableReader::has(const std::string& key) const {
  if (current_key_log) current_key_log->add({&table_, key, {}});
  return table_.contains(key);
}

void TableReader::fail(const std::string& key, const std::string& problem) const {
  const toml::node* n = table_.get(key);
  std::string prefix = n ? where(*n, source_) : display_path(source_) + ": ";
  std::string qualified = display_value(section_.empty() ? key : section_ + "." + key);
  throw ParamError(prefix + "key '" + qualified + "': " + problem);
}

bool TableReader::get_bool(const std::string& key, bool def) {
  note_default(key, def);
  const toml::node* n = node(key);
  if (!n) return def;
  if (auto v = n->value_exact<bool>()) return *v;
  fail(key, "expected true or false");
}

int64_t TableReader::get_int(const std::string& key, int64_t def, int64_t lo, int64_t hi) {
  note_default(key, def);
  const toml::node* n = node(key);
  if (!n) return def;
  auto v = n->value_exact<int64_t>();
  if (!v) fail(key, "expected an integer");
  if (*v < lo || *v > hi) {
    fail(key, "value " + std::to_string(*v) + " is outside [" + std::to_string(lo) + ", " +
                  std::to_string(hi) + "]");
  }
  return *v;
}

double TableReader::get_double(const std::string& key, double def, double lo, double hi) {
  note_default(key, def);
  const toml::node* n = node(key);
  if (!n) return def;
  std::optional<double> v;
  if (auto d = n->value_exact<double>()) v = *d;
  else if (auto i = n->value_exact<int64_t>()) v = static_cast<double>(*i);
  if (!v || !std::isfinite(*v)) fail(key, "expected a number");
  if (*v < lo || *v > hi) {
    std::ostringstream msg;
    msg << "value " << *v << " is outside [" << lo << ", " << hi << "]";
    fail(key, msg.str());
  }
  return *v;
}

std::string TableReader::get_string(const std::string& key, const std::string& def) {
  note_default(key, def);
  const toml::node* n = node(key);
  if (!n) return def;
  if (auto v = n->value_exact<std::string>()) return *v;
  fail(key, "expected a string");
}

std::string TableReader::get_choice(const std::string& key, const std::string& def,
                                    const std::vector<std::string>& choices) {
  std::string v = get_string(key, def);
  for (const auto& c : choices)
    if (c == v) return v;
  std::string list;
  for (const auto& c : choices) list += (list.empty() ? "" : ", ") + c;
  fail(key, "'" + display_value(v) + "' is not one of: " + list);
}

std::vector<std::string> TableReader::get_string_list(const std::string& key,
                                                      const std::vector<std::string>& def) {
  note_default(key, def);
  const toml::node* n = node(key);
  if (!n) return def;
  const toml::array* arr = n->as_array();
  if (!arr) fail(key, "expected a list of strings");
  std::vector<std::string> out;
  for (const auto& el : *arr) {
    auto s = el.value_exact<std::string>();
    if (!s) fail(key, "expected a list of strings");
    out.push_back(*s);
  }
  return out;
}

const toml::table* TableReader::get_table(const std::string& key) {
  const toml::node* n = node(key);
  if (!n) return nullptr;
  if (const toml::table* t = n->as_table()) return t;
  fail(key, "expected a table");
}

const toml::array* TableReader::get_array(const std::string& key) {
  const toml::node* n = node(key);
  if (!n) return nullptr;
  if (const toml::array* a = n->as_array()) return a;
  fail(key, "expected an array");
}

void TableReader::finish() const {
  for (const auto& [k, v] : table_) {
    std::string key(k.str());
    if (!read_.count(key)) {
      std::string qualified = display_value(section_.empty() ? key : section_ + "." + key);
      throw ParamError(where(v, source_) + "unknown key '" + qualified + "'");
    }
  }
}

void apply_set(toml::table& target, const std::string& assignment) {
  auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw ParamError("--set " + display_value(assignment) + ": expected key=value");
  }
  std::string key = assignment.substr(0, eq);
  std::string value = assignment.substr(eq + 1);
  try {
    toml::table parsed = toml::parse("v = " + value, std::string_view{"--set"});
    if (toml::node* n = parsed.get("v")) {
      target.insert_or_assign(key, *n);
      return;
    }
  } catch (const toml::parse_error&) {
    // Not TOML: a bare word such as `dither=atkinson`.
  }
  target.insert_or_assign(key, value);
}

void merge_into(toml::table& base, const toml::table& overrides) {
  for (const auto& [k, v] : overrides) {
    toml::table* inner = base[k].as_table();
    if (inner && v.is_table()) {
      merge_into(*inner, *v.as_table());
    } else {
      base.insert_or_assign(k, v);
    }
  }
}

std::filesystem::path param_base_dir(const toml::node& node) {
  const auto& src = node.source();
  if (!src.path) return {};
  std::error_code ec;
  const std::filesystem::path file(*src.path);
  if (!std::filesystem::is_regular_file(file, ec)) return {};
  return file.parent_path();
}

std::filesystem::path resolve_param_path(const std::filesystem::path& path, const toml::node& node) {
  if (path.is_absolute()) return path;
  return param_base_dir(node) / path;
}

void make_path_absolute(toml::table& t, const std::string& key, const std::filesystem::path& base) {
  if (auto v = t[key].value_exact<std::string>(); v && !v->empty() && std::filesystem::path(*v).is_relative())
    t.insert_or_assign(key, (base / *v).lexically_normal().string());
}

}  // namespace atelier
