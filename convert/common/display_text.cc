#include "convert/common/display_text.h"

#include <cstdint>
#include <cstdio>

namespace atelier {
namespace {

std::string hex_byte(unsigned char c) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "\\x%02X", c);
  return buf;
}

// Length of the well-formed UTF-8 sequence at s[i] (RFC 3629: no overlongs, no surrogates,
// at most U+10FFFF), or 0 if there is none.
size_t utf8_length(std::string_view s, size_t i, uint32_t& cp) {
  const auto b = [&](size_t k) { return static_cast<unsigned char>(s[i + k]); };
  const unsigned char c = b(0);
  const auto cont = [&](size_t k) { return i + k < s.size() && (b(k) & 0xC0) == 0x80; };
  if (c < 0x80) {
    cp = c;
    return 1;
  }
  if (c >= 0xC2 && c <= 0xDF && cont(1)) {
    cp = ((c & 0x1Fu) << 6) | (b(1) & 0x3Fu);
    return 2;
  }
  if (c >= 0xE0 && c <= 0xEF && cont(1) && cont(2)) {
    cp = ((c & 0x0Fu) << 12) | ((b(1) & 0x3Fu) << 6) | (b(2) & 0x3Fu);
    if (cp < 0x800 || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
    return 3;
  }
  if (c >= 0xF0 && c <= 0xF4 && cont(1) && cont(2) && cont(3)) {
    cp = ((c & 0x07u) << 18) | ((b(1) & 0x3Fu) << 12) | ((b(2) & 0x3Fu) << 6) | (b(3) & 0x3Fu);
    if (cp < 0x10000 || cp > 0x10FFFF) return 0;
    return 4;
  }
  return 0;
}

}  // namespace

std::string safe_text(std::string_view bytes) {
  std::string out;
  out.reserve(bytes.size());
  for (size_t i = 0; i < bytes.size();) {
    uint32_t cp = 0;
    const size_t n = utf8_length(bytes, i, cp);
    if (n == 0) {
      out += hex_byte(static_cast<unsigned char>(bytes[i]));
      ++i;
      continue;
    }
    if (cp < 0x20 || cp == 0x7F) {
      switch (cp) {
        case '\n': out += "\\n"; break;
        case '\t': out += "\\t"; break;
        case '\r': out += "\\r"; break;
        case 0x1B: out += "\\e"; break;
        default: out += hex_byte(static_cast<unsigned char>(cp));
      }
    } else if (cp >= 0x80 && cp <= 0x9F) {  // C1 controls (CSI and friends)
      char buf[12];
      std::snprintf(buf, sizeof buf, "\\u{%02X}", static_cast<unsigned>(cp));
      out += buf;
    } else {
      out.append(bytes.substr(i, n));
    }
    i += n;
  }
  return out;
}

std::string display_value(std::string_view value, std::size_t max_bytes) {
  if (value.size() <= max_bytes) return safe_text(value);
  // Cut at a character boundary of the original bytes, then make that part safe.
  size_t cut = max_bytes;
  while (cut > 0 && (static_cast<unsigned char>(value[cut]) & 0xC0) == 0x80) --cut;
  return safe_text(value.substr(0, cut)) + "... (" + std::to_string(value.size()) + " bytes)";
}

std::string redact_quoted(const std::string& message, std::string_view content) {
  std::string out;
  size_t i = 0;
  while (i < message.size()) {
    const char q = message[i];
    const size_t close = (q == '\'' || q == '"') ? message.find(q, i + 1) : std::string::npos;
    if (close == std::string::npos) {
      out += message[i++];
      continue;
    }
    const std::string_view inner(message.data() + i + 1, close - i - 1);
    const bool from_content = !inner.empty() && content.find(inner) != std::string_view::npos;
    out += q;
    out += from_content ? std::string("...") : std::string(inner);
    out += q;
    i = close + 1;
  }
  return out;
}

std::string display_path(const std::filesystem::path& path, std::size_t max_bytes) {
  const std::string& s = path.native();
  if (s.size() <= max_bytes) return safe_text(s);
  return ".../" + display_value(path.filename().native());
}

std::string display_name(const std::filesystem::path& path, std::size_t max_bytes) {
  return display_value(path.filename().native(), max_bytes);
}

}  // namespace atelier
