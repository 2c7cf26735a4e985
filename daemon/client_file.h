// Files that a control-socket client hands the daemon (`submit`, `wood add`), read with the
// client's rights: the client opens the file itself and passes the descriptor (SCM_RIGHTS,
// ControlRequest::files); the path in the request only names the file.
//
// A raw request that names a path but passes no descriptor is served only for a peer with the
// daemon's own rights (same uid, or root): then the daemon may open the path itself, since the
// client could have read it too. Anyone else is refused, so the daemon never reads a file for
// someone who could not.
//
// Errors: ControlError (its message goes back to the client) naming the file and the problem;
// never the file's content. Threading: stateless functions.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "base/unique_fd.h"
#include "daemon/control_server.h"

namespace atelier {

// The file name a job or a sheet is known by: the last component of `path` as the client sent
// it. Throws ControlError when there is none ("", "/", ".", "..").
std::string client_file_name(const std::string& path);

// The open file the request passes as its `index`-th descriptor, or, when it passes none, the
// file at `path` opened by the daemon if the peer has the daemon's rights (see above).
// `usage` tells a refused client what to run instead (e.g. "atelierctl submit FILE --kind K").
// Throws ControlError.
UniqueFd client_file(ControlRequest& request, size_t index, const std::string& path,
                     const std::string& usage);

// Copies the open file `fd` to `dest` (created, mode 0666 less the umask) and fsyncs it.
// Refuses what is not a regular file and a file larger than `max_bytes` (before copying, and
// while copying should it grow); `name` is the file's name for messages. Reads from the
// current offset; nothing is left at `dest` on failure. Throws ControlError.
void copy_client_file(int fd, const std::string& name, const std::filesystem::path& dest,
                      uint64_t max_bytes);

}  // namespace atelier
