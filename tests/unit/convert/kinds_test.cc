// The registry of kinds (convert/kinds.h): its answers, and the rule that kind names and the
// kinds' file names appear as literals only in the registry and in each kind's own folder.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "convert/kinds.h"
#include "convert/common/param_table.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;

TEST(Kinds, EveryKindCanBeValidatedAndConverted) {
  ASSERT_FALSE(kinds().empty());
  std::set<std::string> names;
  for (const KindInfo& k : kinds()) {
    EXPECT_TRUE(names.insert(std::string(k.name)).second) << k.name << " twice";
    EXPECT_NE(k.validate, nullptr) << k.name;
    EXPECT_NE(k.convert, nullptr) << k.name;
    EXPECT_EQ(find_kind(k.name), &k);
    EXPECT_NO_THROW(validate_kind_params(std::string(k.name), toml::table{}, "x.toml")) << k.name;
    // A kind a machine runs names the file the machine is fed, and a driver.
    if (k.machine_input != MachineInput::none) {
      EXPECT_FALSE(k.machine_file.empty()) << k.name;
      EXPECT_FALSE(k.drivers.empty()) << k.name;
    }
    if (k.machine_input == MachineInput::stitch_files) EXPECT_FALSE(k.formats.empty()) << k.name;
  }
  EXPECT_EQ(known_kinds().size(), kinds().size());
  EXPECT_EQ(find_kind("quilt"), nullptr);
  EXPECT_THROW(validate_kind_params("quilt", toml::table{}, "x.toml"), ParamError);
}

TEST(Kinds, DriversTakeTheKindsTheirMachinesRun) {
  EXPECT_EQ(kinds_for_driver("ayab"), (std::vector<std::string>{"knit", "lace"}));
  EXPECT_EQ(kinds_for_driver("ayab", true), (std::vector<std::string>{"knit"}));
  EXPECT_EQ(kinds_for_driver("grbl"), (std::vector<std::string>{"cut", "parquetry", "sketch", "engrave"}));
  EXPECT_EQ(kinds_for_driver("file-drop"), (std::vector<std::string>{"embroidery"}));
  EXPECT_TRUE(kinds_for_driver("plotter").empty());
  for (const std::string& k : kinds_for_driver("grbl"))
    EXPECT_EQ(find_kind(k)->machine_input, MachineInput::gcode) << k;
  EXPECT_TRUE(converts_job_file("lace"));
  EXPECT_FALSE(converts_job_file("knit"));
  EXPECT_FALSE(converts_job_file("quilt"));
  const auto& suffixes = companion_suffixes();
  EXPECT_EQ(suffixes.front(), ".toml");
  EXPECT_NE(std::find(suffixes.begin(), suffixes.end(), ".relax.png"), suffixes.end());
}

// Source text with // comments removed (a comment may name a kind or a file freely).
std::string code_of(const fs::path& file) {
  std::ifstream in(file);
  std::string line, out;
  while (std::getline(in, line)) {
    const size_t c = line.find("//");
    out += (c == std::string::npos ? line : line.substr(0, c)) + "\n";
  }
  return out;
}

struct Source {
  std::string rel;  // path from the source root, "daemon/config.cc"
  std::string code;
};

std::vector<Source> product_sources() {
  std::vector<Source> out;
  const fs::path root = ATELIER_SOURCE_DIR;
  for (const char* dir : {"base", "algorithms", "drivers", "convert", "inventory", "daemon", "tools"}) {
    for (const auto& e : fs::recursive_directory_iterator(root / dir)) {
      const auto ext = e.path().extension();
      if (e.is_regular_file() && (ext == ".cc" || ext == ".h" || ext == ".in"))
        out.push_back({fs::relative(e.path(), root).string(), code_of(e.path())});
    }
  }
  return out;
}

bool in_kind_folder(const std::string& rel) {
  for (const KindInfo& k : kinds())
    if (rel.rfind("convert/" + std::string(k.name) + "/", 0) == 0) return true;
  return rel == "convert/kinds.cc";
}

// Literals that spell a kind's name but mean something else; each with its reason.
bool allowed(const std::string& rel, const std::string& literal) {
  // The laser's layer modes (`mode = "cut" | "engrave"`) are settings, not job kinds (both
  // words are kinds too since the engrave kind came).
  return (literal == "\"cut\"" || literal == "\"engrave\"") &&
         (rel == "convert/common/laser_params.cc" || rel == "algorithms/laser/plan.cc");
}

TEST(Kinds, NoKindNameOrKindFileNameOutsideTheRegistryAndTheKindsFolders) {
  const std::vector<Source> sources = product_sources();
  ASSERT_GT(sources.size(), 100u);  // the tree was found
  // The literals to look for: each kind's name, and every file name a kind's own code writes
  // or reads ("pattern.png", ".relax.png", ...), collected from the kind folders themselves.
  std::set<std::string> literals;
  for (const KindInfo& k : kinds()) literals.insert("\"" + std::string(k.name) + "\"");
  const std::regex file_literal(R"re("\.?[A-Za-z0-9_-]+(\.[A-Za-z0-9_-]+)*\.(png|pdf|svg|json|k|gcode|dst|exp|pes|jef|txt)")re");
  for (const Source& s : sources) {
    if (!in_kind_folder(s.rel)) continue;
    for (std::sregex_iterator it(s.code.begin(), s.code.end(), file_literal), end; it != end; ++it)
      literals.insert(it->str());
  }
  EXPECT_TRUE(literals.count("\"pattern.png\"")) << "the kind folders' file names were not found";
  std::vector<std::string> found;
  for (const Source& s : sources) {
    if (in_kind_folder(s.rel)) continue;
    for (const std::string& lit : literals)
      if (s.code.find(lit) != std::string::npos && !allowed(s.rel, lit)) found.push_back(s.rel + ": " + lit);
  }
  std::string list;
  for (const auto& f : found) list += "\n  " + f;
  EXPECT_TRUE(found.empty()) << "ask the registry (convert/kinds.h) instead:" << list;
}

}  // namespace
}  // namespace atelier
