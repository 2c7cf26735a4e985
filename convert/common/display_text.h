// File names and values are data: before one goes into a PDF, an SVG, JSON or a reason, it is
// turned into valid UTF-8 text that cannot break the line or the terminal it is shown on.
//
// Pure functions; thread-safe.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

namespace atelier {

// `bytes` as valid UTF-8: well-formed UTF-8 sequences are kept; each byte that is not part of
// one becomes "\xNN"; control characters (U+0000-U+001F, U+007F, U+0080-U+009F) become
// "\n", "\t", "\r", "\e" or "\xNN" / "\u{NN}"; a backslash stays a backslash.
std::string safe_text(std::string_view bytes);

// safe_text(value), cut to its first `max_bytes` bytes (never inside a character) plus
// "... (N bytes)" when the value is longer than `max_bytes`.
std::string display_value(std::string_view value, std::size_t max_bytes = 80);

// A path for a message: safe_text of the whole path when it is at most `max_bytes` long,
// otherwise ".../" + the file name (itself cut by display_value to 80 bytes), so the name is
// never lost and the whole stays short.
std::string display_path(const std::filesystem::path& path, std::size_t max_bytes = 120);

// `message` with every quoted part ('...' or "...") that occurs in `content` replaced by
// '...': for a parser's message about a file that must not echo what the file holds.
std::string redact_quoted(const std::string& message, std::string_view content);

// The file name of `path` for a message: display_value(filename, max_bytes).
std::string display_name(const std::filesystem::path& path, std::size_t max_bytes = 120);

}  // namespace atelier
