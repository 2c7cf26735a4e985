// The kind a job file names (`kind = "..."` in incoming/NAME.toml). The TOML is untrusted and
// toml++ 3.3.0 crashes on some inputs, so the daemon never calls this itself: it runs
// `atelier-convert --job-kind FILE` (daemon/job_kind_probe.h), where a crash costs one job.
//
// Messages never echo the file's content (the file may be somebody else's, e.g. a hard link
// or a copy of /etc/passwd): they give the file's name, the line and column, and what was
// wrong, with anything quoted from the file left out.
// Pure apart from reading `file`; any thread.
#pragma once

#include <filesystem>
#include <string>

namespace atelier {

struct JobFileKind {
  std::string kind;     // a known kind that converts job files; "" when `problem` is set
  std::string problem;  // why the file is not a job, naming `shown_name`; "" when fine
};

// Reads `file` (shown as `shown_name` in messages) and returns its kind, or why it has none:
// not TOML, no kind, an unknown kind, or a kind that converts an image.
JobFileKind read_job_file_kind(const std::filesystem::path& file, const std::string& shown_name);

// A toml++ parse error's description with whatever it quotes from the input removed
// ("expected '=', saw ':'" -> "expected '='"; "cannot redefine existing integer 'a'" ->
// "cannot redefine existing integer '...'"). Exposed for tests.
std::string description_without_content(const std::string& description);

}  // namespace atelier
