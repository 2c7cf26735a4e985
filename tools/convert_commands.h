// The atelier-convert commands that are not job kinds (issue 8): `line` draws one hand-drawn
// pencil line from its two end points (convert/sketch/line_job.h), `pencil-profile` learns a
// pencil profile from a scan of its lines (algorithms/pencil/profile.h) or from the modelled
// reference scan of a shipped grade. Each parses its own arguments (argv[0] = the command's
// name) and returns the exit code: 0 ok, 1 bad input (message on stderr), 2 usage.
// Single-threaded; called from main().
#pragma once

#include <string>
#include <toml++/toml.h>

namespace atelier::convert_tool {

// Reads a whole TOML file (also /dev/stdin, which cannot be sized or seeked). Throws ParamError
// "FILE:LINE: ..." naming the file.
toml::table parse_toml_file(const std::string& path);

int run_pencil_profile(int argc, char** argv);
int run_line(int argc, char** argv);

}  // namespace atelier::convert_tool
