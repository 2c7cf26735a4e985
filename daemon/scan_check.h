// Decodes the scans a client hands to `wood add` in an `atelier-convert --decode-check` child
// before the daemon adds them to the wood library: image decoders (libpng, libjpeg, libtiff,
// libwebp via OpenCV) then meet a client's bytes only where a crash or a runaway allocation
// costs that one request, never atelierd. Once a file decoded there, the daemon's own decode of
// it (inventory/wood_library's add_sheet) sees bytes that are known to decode.
//
// Threading: blocks the calling thread (the control socket's) for at most the child's timeout.
#pragma once

#include <filesystem>
#include <vector>

#include "daemon/child_process.h"

namespace atelier {

// Throws BadInput naming the file and the problem when a file does not decode (or the child
// crashed, ran out of memory or time on it). `exe`: atelier-convert.
void check_scans_decode(const std::filesystem::path& exe, const std::vector<std::filesystem::path>& files,
                        const ChildLimits& limits);

}  // namespace atelier
