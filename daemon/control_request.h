// One control-socket request line parsed (docs/control-protocol.md): {"verb": "...",
// "args": {...}}. Split out of the control server so that it can be tested and fuzzed alone.
// Pure; thread-safe.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace atelier {

// JSON nested deeper than this (objects and arrays) is refused: copying or printing a value
// recurses once per level, and a 200 KB line of "[[[[..." overflowed the daemon's stack. The
// protocol's requests are at most 3 levels deep.
inline constexpr int kMaxRequestDepth = 32;

// The line's part of a ControlRequest (control_server.h adds the peer and passed files).
struct ParsedRequest {
  std::string verb;
  nlohmann::json args = nlohmann::json::object();  // "args" as sent (any type); {} when absent
};

// Throws ControlError with the message the client gets back as {"ok": false, "error": ...}:
// "request is not valid JSON", "request is nested deeper than 32 levels", "request needs a
// \"verb\" string".
ParsedRequest parse_request(const std::string& line);

}  // namespace atelier
