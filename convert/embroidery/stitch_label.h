// The design label the stitch-file headers carry (DST "LA:", PEC "LA:"): the design's name as
// printable ASCII, each non-ASCII character one '_', cut or space-padded to 16 bytes, as the
// machines show it. Pure, thread-safe.
#pragma once

#include <string>

namespace atelier::embroidery {

inline std::string label16(const std::string& name) {
  std::string out;
  for (unsigned char c : name) {
    if (out.size() == 16) break;
    if (c >= 0x80 && c < 0xC0) continue;  // UTF-8 continuation: its lead byte already gave '_'
    out += (c >= 0x20 && c < 0x7F) ? static_cast<char>(c) : '_';
  }
  out.resize(16, ' ');
  return out;
}

}  // namespace atelier::embroidery
