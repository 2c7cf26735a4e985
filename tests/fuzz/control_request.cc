// One control-socket request line (without its "\n") through the daemon's parser, and the
// error reply the server would send for it.
#include <string>

#include "daemon/control_request.h"
#include "daemon/control_server.h"
#include "tests/fuzz/fuzz_targets.h"

int fuzz_control_request(const uint8_t* data, size_t size) {
  if (size > atelier::fuzz::kMaxFuzzInput) return 0;
  const std::string line(reinterpret_cast<const char*>(data), size);
  try {
    const atelier::ParsedRequest r = atelier::parse_request(line);
    (void)r.args.dump();
  } catch (const atelier::ControlError& e) {
    const nlohmann::json reply = {{"ok", false}, {"error", e.what()}};
    (void)reply.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  }
  return 0;
}
