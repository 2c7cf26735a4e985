// Parameter tables: the input as a daemon config (parse_config); as a sidecar, merged over each
// kind's configured defaults and validated as that kind's parameters, as a job's are; and each
// of its lines as a `--set key=value` over the same defaults.
#include <map>
#include <string>
#include <string_view>
#include <toml++/toml.h>

#include "base/error.h"
#include "convert/common/param_table.h"
#include "convert/kinds.h"
#include "daemon/config.h"
#include "tests/fuzz/fuzz_targets.h"

namespace {

// Every kind's defaults as a minimal config gives them.
const std::map<std::string, toml::table>& kind_defaults() {
  static const std::map<std::string, toml::table> defaults =
      atelier::parse_config("[spool]\ndir = \"/nonexistent/spool\"\n", "atelierd.toml").kind_defaults;
  return defaults;
}

void validate_each_kind(const toml::table& overrides, const std::string& source) {
  for (const atelier::KindInfo& kind : atelier::kinds()) {
    const std::string name(kind.name);
    toml::table params;
    if (auto it = kind_defaults().find(name); it != kind_defaults().end()) params = it->second;
    atelier::merge_into(params, overrides);
    try {
      atelier::validate_kind_params(name, params, source);
    } catch (const atelier::BadInput&) {
    }
  }
}

}  // namespace

int fuzz_param_table(const uint8_t* data, size_t size) {
  if (size > atelier::fuzz::kMaxFuzzInput) return 0;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)atelier::parse_config(text, "atelierd.toml");
  } catch (const atelier::BadInput&) {
  }
  try {
    validate_each_kind(toml::parse(text, std::string_view{"photo.png.toml"}), "photo.png.toml");
  } catch (const toml::parse_error&) {
  }
  toml::table sets;
  std::string_view rest(text);
  while (!rest.empty()) {
    const size_t nl = rest.find('\n');
    const std::string line(rest.substr(0, nl));
    rest = nl == std::string_view::npos ? std::string_view() : rest.substr(nl + 1);
    try {
      atelier::apply_set(sets, line);
    } catch (const atelier::BadInput&) {
    }
  }
  validate_each_kind(sets, "--set");
  return 0;
}
