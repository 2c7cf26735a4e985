// Command-line parsing with one convention for every atelier program: --help and --version
// print and exit 0, a usage error prints CLI11's message and exits 2 (as getopt programs and
// CUPS's tools do). Header-only, so that base/ itself does not link CLI11.
#pragma once

#include <optional>

#include <CLI/CLI.hpp>

namespace atelier {

// Parses argv into `app`. Returns the exit status when the program is to stop now (help,
// version: 0; usage error: 2), or nothing when it is to go on.
inline std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;  // app.exit prints the help, the version or the error
  }
  return std::nullopt;
}

}  // namespace atelier
