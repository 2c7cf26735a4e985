// The Hershey fonts engraved IDs are written in, read from Debian's hershey-fonts-data (.jhf
// files in /usr/share/hershey-fonts, or in $HERSHEY_FONTS_DIR when set, as libhersheyfont
// documents) by libhersheyfont, for algorithms/laser/hershey_text.h.
//
// Threading: thread-safe. Each font file is read once, on first use, under a mutex, and kept
// for the life of the process; later calls only read the immutable cache.
// Errors: InternalError for a font file that is missing or cannot be read (the message names
// the path: an installation problem, not the user's), std::invalid_argument for a name that is
// not a plain font name (so a caller's string never reaches outside the font folder).
#pragma once

#include <string>

#include "algorithms/laser/hershey_text.h"

namespace atelier {

// The font `name` (a .jhf name without extension: "rowmans", "futural", "rowmand", ...).
// The reference stays valid for the life of the process.
const laser::HersheyFont& hershey_font(const std::string& name = "rowmans");

}  // namespace atelier
