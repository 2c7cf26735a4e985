// What a program's CLI11 `--help` lists: its subcommands and its options, as a user reads them
// (tests of the man pages and of the shell completion compare these with what they document).
// Pure text parsing; any thread.
#pragma once

#include <set>
#include <sstream>
#include <string>

namespace atelier::test {

struct CliHelp {
  std::set<std::string> subcommands;  // "status", "list", ...
  std::set<std::string> options;      // every name of every option: "-h", "--help", "--socket"
};

// Parses CLI11's help layout: a section title at the start of a line ("Options:",
// "Subcommands:", "Positionals:"), its entries indented by two spaces, the entry's names
// first ("-c,--config TEXT=..."), continuation lines indented further.
inline CliHelp parse_cli_help(const std::string& text) {
  CliHelp help;
  std::istringstream in(text);
  std::string section;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] != ' ') {
      section = line;
      continue;
    }
    if (line.size() < 3 || line.compare(0, 2, "  ") != 0 || line[2] == ' ') continue;
    const std::string names = line.substr(2, line.find(' ', 2) - 2);
    if (section == "Subcommands:") {
      help.subcommands.insert(names);
    } else if (section == "Options:") {
      std::istringstream split(names);
      for (std::string name; std::getline(split, name, ',');) help.options.insert(name);
    }
  }
  return help;
}

}  // namespace atelier::test
