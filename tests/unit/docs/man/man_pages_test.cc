// The man pages (docs/man/*.scd) against the programs they describe: every verb, sub-verb and
// option the built programs' --help lists is documented where a reader looks for it (a
// verb's options under that verb), every kind of the registry has its entry, the FILES name
// the paths the code uses, and every page is built into roff and a gzip Debian accepts.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "convert/kinds.h"
#include "daemon/config.h"
#include "tests/e2e/daemon_harness.h"
#include "tests/support/cli_help.h"

namespace {

namespace fs = std::filesystem;
using atelier::test::binary;
using atelier::test::parse_cli_help;
using atelier::test::read_file;
using atelier::test::run_command;

const fs::path kManDir = fs::path(ATELIER_SOURCE_DIR) / "docs" / "man";

// One definition in a page: a line at the start of a section's text that begins with a bold
// term ("*list* [*--state* _STATE_] ...", "*-c*, *--config* _FILE_"), and the text under it
// up to the next such line or section.
struct Entry {
  std::string term;                // the first bold text: "list", "wood add", "-c", "knit"
  std::set<std::string> options;   // every bold option in the entry: "--state", "-c", ...
};

struct Page {
  fs::path file;
  std::map<std::string, std::vector<Entry>> sections;  // "OPTIONS" -> its entries
  std::map<std::string, std::string> text;             // "FILES" -> its text
};

std::set<std::string> bold_options(const std::string& text) {
  static const std::regex option(R"(\*(--?[A-Za-z0-9][A-Za-z0-9-]*)\*)");
  std::set<std::string> out;
  for (std::sregex_iterator it(text.begin(), text.end(), option), end; it != end; ++it)
    out.insert((*it)[1]);
  return out;
}

Page read_page(const std::string& name) {
  Page page{kManDir / (name + ".scd"), {}, {}};
  std::istringstream in(read_file(page.file));
  std::string section;
  Entry* entry = nullptr;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("# ", 0) == 0) {
      section = line.substr(2);
      entry = nullptr;
      continue;
    }
    page.text[section] += line + "\n";
    if (line.size() > 1 && line[0] == '*') {
      const size_t close = line.find('*', 1);
      page.sections[section].push_back({line.substr(1, close - 1), {}});
      entry = &page.sections[section].back();
    }
    if (entry) {
      for (const std::string& o : bold_options(line)) entry->options.insert(o);
    }
  }
  return page;
}

// The options a page documents under entries whose term is `term` (every one, if empty).
std::set<std::string> documented(const Page& page, const std::string& section,
                                 const std::string& term = "") {
  std::set<std::string> out;
  auto found = page.sections.find(section);
  if (found == page.sections.end()) return out;
  for (const Entry& e : found->second)
    if (term.empty() || e.term == term) out.insert(e.options.begin(), e.options.end());
  return out;
}

std::set<std::string> terms(const Page& page, const std::string& section) {
  std::set<std::string> out;
  auto found = page.sections.find(section);
  if (found == page.sections.end()) return out;
  for (const Entry& e : found->second) out.insert(e.term);
  return out;
}

atelier::test::CliHelp help_of(const std::string& program, std::vector<std::string> args = {}) {
  std::vector<std::string> argv = {binary(program).string()};
  argv.insert(argv.end(), args.begin(), args.end());
  argv.push_back("--help");
  const auto run = run_command(argv);
  EXPECT_EQ(run.exit_code, 0) << program << " --help: " << run.err;
  return parse_cli_help(run.out);
}

// `want` minus what `have` holds (and minus -h/--help, which OPTIONS documents once).
std::vector<std::string> missing(const std::set<std::string>& want, const std::set<std::string>& have) {
  std::vector<std::string> out;
  for (const std::string& w : want)
    if (!have.count(w) && w != "-h" && w != "--help") out.push_back(w);
  return out;
}

std::string joined(const std::vector<std::string>& words) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

TEST(ManPages, AtelierctlDocumentsEveryVerbWithItsOptions) {
  const Page page = read_page("atelierctl.1");
  const auto top = help_of("atelierctl");
  ASSERT_TRUE(top.subcommands.count("list")) << "atelierctl --help lists no verbs";
  EXPECT_EQ(missing(top.options, documented(page, "OPTIONS")), std::vector<std::string>{})
      << page.file << ": OPTIONS";
  EXPECT_TRUE(documented(page, "OPTIONS").count("--help")) << page.file << ": -h, --help";

  // Every verb has an entry in COMMANDS ("*wood list*" counts for wood), and nothing else has.
  std::set<std::string> verbs_in_page;
  for (const std::string& t : terms(page, "COMMANDS")) verbs_in_page.insert(t.substr(0, t.find(' ')));
  EXPECT_EQ(verbs_in_page, top.subcommands) << page.file << ": COMMANDS against atelierctl --help";

  for (const std::string& verb : top.subcommands) {
    const auto help = help_of("atelierctl", {verb});
    if (!help.subcommands.empty()) {
      for (const std::string& sub : help.subcommands) {
        const std::string term = verb + " " + sub;
        EXPECT_TRUE(terms(page, "COMMANDS").count(term)) << page.file << ": no entry *" << term << "*";
        EXPECT_EQ(missing(help_of("atelierctl", {verb, sub}).options, documented(page, "COMMANDS", term)),
                  std::vector<std::string>{})
            << page.file << ": options of '" << term << "' not under its entry";
      }
      continue;
    }
    EXPECT_EQ(missing(help.options, documented(page, "COMMANDS", verb)), std::vector<std::string>{})
        << page.file << ": options of '" << verb << "' not under its entry";
  }
}

TEST(ManPages, AtelierConvertDocumentsEveryOptionCommandAndKind) {
  const Page page = read_page("atelier-convert.1");
  const auto main_help = help_of("atelier-convert");
  ASSERT_TRUE(main_help.options.count("--set"));
  EXPECT_EQ(missing(main_help.options, documented(page, "OPTIONS")), std::vector<std::string>{})
      << page.file << ": OPTIONS";

  // The commands that are not kinds: those main() tells apart by argv[1] before parsing.
  const std::string source = read_file(fs::path(ATELIER_SOURCE_DIR) / "tools" / "atelier-convert.cc");
  const std::regex command(R"re(std::string\(argv\[1\]\) == "([^"]+)")re");
  std::set<std::string> commands;
  for (std::sregex_iterator it(source.begin(), source.end(), command), end; it != end; ++it)
    commands.insert((*it)[1]);
  ASSERT_TRUE(commands.count("line")) << "no commands found in tools/atelier-convert.cc";
  for (const std::string& c : commands) {
    if (main_help.options.count(c)) continue;  // an option main() answers early (--version): in OPTIONS
    EXPECT_TRUE(terms(page, "COMMANDS").count(c)) << page.file << ": no entry *" << c << "* in COMMANDS";
    if (c.rfind("-", 0) == 0) continue;  // --list-kinds, ...: no options of their own
    EXPECT_EQ(missing(help_of("atelier-convert", {c}).options, documented(page, "COMMANDS", c)),
              std::vector<std::string>{})
        << page.file << ": options of '" << c << "' not under its entry";
  }

  const std::vector<std::string>& kinds = atelier::known_kinds();
  EXPECT_EQ(terms(page, "KINDS"), std::set<std::string>(kinds.begin(), kinds.end()))
      << page.file << ": KINDS against the registry (convert/kinds.cc)";
}

TEST(ManPages, AtelierdDocumentsEveryOptionAndTheFilesItUses) {
  const Page page = read_page("atelierd.8");
  const auto run = run_command({binary("atelierd").string(), "--help"});
  const auto help = parse_cli_help(run.out);
  ASSERT_TRUE(help.options.count("--config")) << run.out;
  EXPECT_EQ(missing(help.options, documented(page, "OPTIONS")), std::vector<std::string>{})
      << page.file << ": OPTIONS";

  std::smatch config_default;
  ASSERT_TRUE(std::regex_search(run.out, config_default, std::regex(R"(--config TEXT=(\S+))"))) << run.out;
  const atelier::Config defaults;
  for (const std::string path : {config_default[1].str(), defaults.store_path.string(),
                                 defaults.socket_path.string()}) {
    EXPECT_NE(page.text.at("FILES").find("_" + path + "_"), std::string::npos)
        << page.file << ": FILES does not name " << path;
  }
}

TEST(ManPages, EveryPageNamesEveryKind) {
  // A reader of atelierctl(1) or atelierd(8) learns which kinds there are, as the registry has them.
  for (const std::string name : {"atelierctl.1", "atelierd.8"}) {
    const std::string text = read_file(kManDir / (name + ".scd"));
    for (const std::string& kind : atelier::known_kinds())
      EXPECT_NE(text.find("*" + kind + "*"), std::string::npos) << name << ".scd does not name " << kind;
  }
}

TEST(ManPages, EveryPageIsBuiltWithTheVersionAndGzippedWithoutNameOrTime) {
  int pages = 0;
  for (const auto& e : fs::directory_iterator(kManDir)) {
    if (e.path().extension() != ".scd") continue;
    ++pages;
    const std::string page = e.path().stem().string();  // atelierctl.1
    const fs::path roff = fs::path(ATELIER_BINARY_DIR) / "docs" / "man" / page;
    const std::string text = read_file(roff);
    ASSERT_FALSE(text.empty()) << roff << " is not built (the `man` target is part of ALL)";
    EXPECT_NE(text.find(".TH \""), std::string::npos) << roff << " is not roff";
    EXPECT_NE(text.find("\"atelier " ATELIER_VERSION "\""), std::string::npos) << roff << ": no version";
    EXPECT_EQ(text.find("@VERSION@"), std::string::npos) << roff;

    // Debian policy: gzip -9n, no original name and no time stamp, so builds are reproducible.
    const std::string gz = read_file(roff.string() + ".gz");
    ASSERT_GE(gz.size(), 10u) << roff << ".gz";
    EXPECT_EQ(static_cast<unsigned char>(gz[0]), 0x1f) << roff << ".gz is not gzip";
    EXPECT_EQ(static_cast<unsigned char>(gz[1]), 0x8b) << roff << ".gz is not gzip";
    EXPECT_EQ(gz[3] & 0x08, 0) << roff << ".gz keeps the file's name";
    EXPECT_EQ(gz.substr(4, 4), std::string(4, '\0')) << roff << ".gz keeps a time stamp";
    EXPECT_EQ(static_cast<unsigned char>(gz[8]), 2) << roff << ".gz is not compressed with -9";
    const auto unzipped = run_command({"/bin/gzip", "-dc", roff.string() + ".gz"});
    EXPECT_EQ(unzipped.out, text) << roff << ".gz is not the page";
  }
  EXPECT_GE(pages, 3);
}

}  // namespace
