// config/atelierd.toml documents every key the code reads, and only those, each at its default,
// and its man page atelierd.toml(5) (docs/man/atelierd.toml.5.scd) names the same keys with the
// same values: so neither can drift from the readers (daemon/config.cc, each kind's params reader
// through the kinds registry, [laser] and [[device]]).
//
// The file shows every key but [spool] dir commented out ("# key = default"). The test removes
// those "# " to get the file a user would have with every key set, reads it with the daemon's
// own loader while a ParamKeyLog (convert/common/param_table.h) records which keys of which
// tables the readers asked for and with which defaults, and compares.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "convert/common/param_table.h"
#include "convert/kinds.h"
#include "daemon/config.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;

const fs::path kSourceDir = ATELIER_SOURCE_DIR;
const fs::path kConfigFile = kSourceDir / "config" / "atelierd.toml";
const fs::path kManPage = kSourceDir / "docs" / "man" / "atelierd.toml.5.scd";

std::string slurp(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

const std::regex kCommentedHeader(R"re(^#\s?(\[\[?[A-Za-z0-9_.]+\]\]?)\s*$)re");
const std::regex kCommentedKey(R"re(^#\s?([A-Za-z_][A-Za-z0-9_]*\s*=.*)$)re");

// The text with every commented-out key line and section header made live.
std::string uncommented(const std::string& text) {
  std::istringstream in(text);
  std::string line, out;
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_match(line, m, kCommentedHeader) || std::regex_match(line, m, kCommentedKey))
      line = m[1].str();
    out += line + "\n";
  }
  return out;
}

// "VALUE" of a line "key = VALUE   # comment" (the comment and spaces cut; '#' in a string kept).
std::string value_text(const std::string& rest) {
  bool quoted = false;
  size_t end = rest.size();
  for (size_t i = 0; i < rest.size(); ++i) {
    if (rest[i] == '"') quoted = !quoted;
    if (rest[i] == '#' && !quoted) {
      end = i;
      break;
    }
  }
  std::string v = rest.substr(0, end);
  while (!v.empty() && v.back() == ' ') v.pop_back();
  while (!v.empty() && v.front() == ' ') v.erase(v.begin());
  return v;
}

// Section path -> key -> the values shown for it (several for [[array]] entries), from the text
// of the file with its keys made live: "" is the top level, "laser.layer" each [[laser.layer]].
using ShownKeys = std::map<std::string, std::map<std::string, std::set<std::string>>>;
ShownKeys shown_keys(const std::string& live_text) {
  ShownKeys out;
  std::istringstream in(live_text);
  std::string line, section;
  const std::regex header(R"re(^\[\[?([A-Za-z0-9_.]+)\]\]?\s*(#.*)?$)re");
  const std::regex key(R"re(^([A-Za-z_][A-Za-z0-9_]*)\s*=(.*)$)re");
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_match(line, m, header)) {
      section = m[1].str();
      out[section];
    } else if (std::regex_match(line, m, key)) {
      out[section][m[1].str()].insert(value_text(m[2].str()));
    }
  }
  return out;
}

struct TableInfo {
  std::string path;     // "knit", "laser.layer", "device"
  bool in_array = false;  // an entry of an array of tables
};

void index_tables(const toml::table& t, const std::string& path, bool in_array,
                  std::map<const toml::table*, TableInfo>& out) {
  out[&t] = {path, in_array};
  for (const auto& [k, v] : t) {
    const std::string sub = path.empty() ? std::string(k.str()) : path + "." + std::string(k.str());
    if (const toml::table* inner = v.as_table()) index_tables(*inner, sub, false, out);
    if (const toml::array* a = v.as_array())
      for (const auto& el : *a)
        if (const toml::table* entry = el.as_table()) index_tables(*entry, sub, true, out);
  }
}

// What the readers asked, by section path: key -> the tables asked and the defaults given.
struct Asked {
  std::map<std::string, std::set<std::string>> keys;
  std::vector<std::pair<TableInfo, ParamKeyUse>> defaults;  // uses that carry a default
};

// Reads the live file with the daemon's loader and records what the readers asked.
Asked asked_by_the_code(const toml::table& root) {
  std::map<const toml::table*, TableInfo> tables;
  index_tables(root, "", false, tables);
  ParamKeyLog log;
  config_from_table(root, kConfigFile.string());
  Asked asked;
  for (const ParamKeyUse& use : log.uses()) {
    auto it = tables.find(use.table);
    if (it == tables.end()) continue;  // a reader's own empty table for an absent section
    asked.keys[it->second.path].insert(use.key);
    if (use.default_value.contains("v")) asked.defaults.emplace_back(it->second, use);
  }
  return asked;
}

// A key the readers ask for that the file documents in another place, with the reason; "" if none.
std::string documented_elsewhere(const std::string& section, const std::string& key, const Asked& asked) {
  if (!section.empty() && asked.keys.at("").count(key))
    return "the daemon hands its own [" + key + "] section to the kinds that read it";
  if (key == "kind" && converts_job_file(section)) return "a job file's own key, naming its kind";
  return "";
}

// "[knit] width" for messages.
std::string name(const std::string& section, const std::string& key) {
  return section.empty() ? "[" + key + "]" : "[" + section + "] " + key;
}

class AtelierdToml : public ::testing::Test {
 protected:
  void SetUp() override {
    text_ = slurp(kConfigFile);
    ASSERT_FALSE(text_.empty()) << kConfigFile;
    live_text_ = uncommented(text_);
    live_ = toml::parse(live_text_, std::string_view{kConfigFile.string()});
  }
  std::string text_, live_text_;
  toml::table live_;
};

TEST_F(AtelierdToml, TheFileAsShippedAndWithEveryKeySetParsesWithTheDaemonsLoader) {
  EXPECT_NO_THROW(load_config(kConfigFile));
  try {
    config_from_table(live_, kConfigFile.string());
  } catch (const std::exception& e) {
    ADD_FAILURE() << "with every commented-out key set: " << e.what();
  }
  // Only [spool] dir is live: everything else is shown at its default, commented out.
  const toml::table shipped = toml::parse(text_, std::string_view{kConfigFile.string()});
  std::vector<std::string> live_keys;
  for (const auto& [section, node] : shipped) {
    ASSERT_TRUE(node.is_table()) << "[" << section << "]: only tables at the top level";
    for (const auto& [key, value] : *node.as_table()) live_keys.push_back(std::string(section.str()) + "." + std::string(key.str()));
  }
  EXPECT_EQ(live_keys, std::vector<std::string>{"spool.dir"});
}

TEST_F(AtelierdToml, EveryKeyTheCodeReadsIsDocumentedInItsSectionAndNoOther) {
  const Asked asked = asked_by_the_code(live_);
  ShownKeys shown = shown_keys(live_text_);
  // A section is a key of the table above it: [laser] of the top level, [[laser.layer]] of [laser].
  for (const auto& [section, keys] : ShownKeys(shown)) {
    if (section.empty()) continue;
    const size_t dot = section.rfind('.');
    shown[dot == std::string::npos ? "" : section.substr(0, dot)][section.substr(dot + 1)];
  }
  ASSERT_TRUE(asked.keys.count(""));
  ASSERT_GT(asked.keys.size(), 10u) << "the readers were not recorded";
  for (const auto& [section, keys] : asked.keys)
    for (const std::string& key : keys) {
      if (!documented_elsewhere(section, key, asked).empty()) continue;
      EXPECT_TRUE(shown.count(section) && shown[section].count(key))
          << kConfigFile.string() << " does not document " << name(section, key);
    }
  for (const auto& [section, keys] : shown)
    for (const auto& [key, values] : keys)
      EXPECT_TRUE(asked.keys.count(section) && asked.keys.at(section).count(key))
          << kConfigFile.string() << " documents " << name(section, key) << ", which no reader reads";
  // Every kind has its section (iterating the registry, never naming a kind).
  for (const KindInfo& kind : kinds()) EXPECT_TRUE(shown.count(std::string(kind.name))) << kind.name;
}

TEST_F(AtelierdToml, EveryDriverHasAnExampleDevice) {
  std::set<std::string> drivers, shown;
  for (const KindInfo& kind : kinds())
    for (const DriverUse& d : kind.drivers) drivers.emplace(d.driver);
  if (const toml::array* devices = live_["device"].as_array())
    for (const auto& d : *devices)
      if (auto driver = d.as_table()->get("driver")) shown.insert(driver->value_or(std::string()));
  EXPECT_EQ(shown, drivers);
}

// Whether the file's `value` is the reader's default `def` (a whole number stands for a float).
bool same_value(const toml::node& value, const toml::node& def) {
  if (def.is_floating_point() && (value.is_integer() || value.is_floating_point()))
    return value.value<double>() == def.value<double>();
  if (def.is_array() && value.is_array()) return *def.as_array() == *value.as_array();
  if (def.type() != value.type()) return false;
  if (def.is_string()) return def.value<std::string>() == value.value<std::string>();
  if (def.is_integer()) return def.value<int64_t>() == value.value<int64_t>();
  if (def.is_boolean()) return def.value<bool>() == value.value<bool>();
  return false;
}

TEST_F(AtelierdToml, EveryKeyIsShownAtItsDefault) {
  const Asked asked = asked_by_the_code(live_);
  size_t checked = 0;
  for (const auto& [table, use] : asked.defaults) {
    // The three [[laser.layer]] tables shown are the layers used when none is given, not
    // each key's default (a layer's name defaults to its colour).
    if (table.path == "laser.layer") continue;
    const toml::node& def = *use.default_value.get("v");
    // An empty string is "none": the file shows an example (a device's port, a folder).
    if (def.is_string() && def.value<std::string>()->empty()) continue;
    const toml::node* value = use.table->get(use.key);
    if (!value) continue;  // not shown in this [[device]] example (another driver's key)
    ++checked;
    std::ostringstream want, got;
    toml::table shown_value;
    shown_value.insert("v", *value);
    want << use.default_value;
    got << shown_value;
    EXPECT_TRUE(same_value(*value, def)) << name(table.path, use.key) << " is shown as " << got.str()
                                         << " but defaults to " << want.str();
  }
  EXPECT_GT(checked, 100u);
}

// The man page's sections ("## [knit]", "## [[device]]") and their keys ("*max\_float* = 4"),
// with scdoc's escapes undone.
ShownKeys man_page_keys(const std::string& scd) {
  ShownKeys out;
  std::istringstream in(scd);
  std::string line, section;
  const std::regex header(R"re(^## \[\[?([A-Za-z0-9_.\\]+)\]\]?\s*$)re");
  const std::regex key(R"re(^\*([A-Za-z0-9_\\]+)\* = (.*)$)re");
  auto unescape = [](std::string s) {
    std::string out;
    for (size_t i = 0; i < s.size(); ++i)
      if (!(s[i] == '\\' && i + 1 < s.size())) out += s[i];
      else out += s[++i];
    return out;
  };
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_match(line, m, header)) {
      section = unescape(m[1].str());
      out[section];
    } else if (line.rfind("# ", 0) == 0) {
      section.clear();  // FILES, SEE ALSO: no longer the sections
    } else if (std::regex_match(line, m, key) && !section.empty()) {
      out[section][unescape(m[1].str())].insert(unescape(m[2].str()));
    }
  }
  return out;
}

TEST_F(AtelierdToml, TheManPageNamesEveryKeyOfTheFileWithTheSameValue) {
  const std::string scd = slurp(kManPage);
  ASSERT_FALSE(scd.empty()) << kManPage;
  const ShownKeys man = man_page_keys(scd);
  ShownKeys file = shown_keys(live_text_);
  file.erase("");
  for (const auto& [section, keys] : file) {
    ASSERT_TRUE(man.count(section)) << kManPage.string() << " has no section \"## [" << section << "]\"";
    for (const auto& [key, values] : keys) {
      ASSERT_TRUE(man.at(section).count(key)) << kManPage.string() << " does not describe " << name(section, key);
      for (const std::string& v : man.at(section).at(key))
        EXPECT_TRUE(values.count(v)) << kManPage.string() << ": " << name(section, key) << " = " << v
                                     << ", but " << kConfigFile.string() << " shows " << *values.begin();
    }
  }
  for (const auto& [section, keys] : man) {
    EXPECT_TRUE(file.count(section)) << kManPage.string() << " describes [" << section << "], which "
                                     << kConfigFile.string() << " does not have";
    for (const auto& [key, values] : keys)
      EXPECT_TRUE(file.count(section) && file.at(section).count(key))
          << kManPage.string() << " describes " << name(section, key) << ", which " << kConfigFile.string()
          << " does not have";
  }
}

}  // namespace
}  // namespace atelier
