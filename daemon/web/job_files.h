// A job's output files as the web server serves them (docs/web.md): only from the job's own
// output folder in the spool (done/ID/ or failed/ID/), by bare name, never through a symbolic
// link, never anything outside the spool.
// Threading: stateless functions; any thread.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "base/unique_fd.h"

namespace atelier::web {

struct OpenedFile {
  UniqueFd fd;
  uint64_t size = 0;  // bytes, from fstat of the open file
};

// Opens `name` in `output_dir` for reading if, and only if:
// - `output_dir` is lexically <spool_dir>/done/<digits> or <spool_dir>/failed/<digits>;
// - `name` is one path component: not empty, no '/', no NUL, not "." or "..";
// - neither done|failed, nor <digits>, nor `name` is a symbolic link (each opened with
//   O_NOFOLLOW relative to the one before, so nothing can be swapped in between);
// - it is a regular file.
// nullopt otherwise (the caller answers 404 and says no more).
std::optional<OpenedFile> open_job_file(const std::filesystem::path& spool_dir,
                                        const std::filesystem::path& output_dir, const std::string& name);

// The Content-Type to serve a file under, from its extension ("image/png", "image/svg+xml",
// "application/pdf", "text/plain; charset=utf-8", ...; "application/octet-stream" otherwise).
std::string content_type_for(const std::string& name);

// Whether the browser may show it in place (pictures, text, JSON); anything else is sent as a
// download (Content-Disposition: attachment).
bool shown_inline(const std::string& name);

// The previews of a job of `kind` among its `outputs`, in the kind's order (kinds.h).
std::vector<std::string> preview_files(const std::string& kind, const std::vector<std::string>& outputs);

}  // namespace atelier::web
