#include "daemon/control_request.h"

#include "daemon/control_server.h"

namespace atelier {

ParsedRequest parse_request(const std::string& line) {
  // The callback sees every value's depth as it is parsed; a deep one stops the parse there,
  // before the tree (whose copies recurse per level) is built any deeper.
  auto limit = [](int depth, nlohmann::json::parse_event_t event, nlohmann::json&) {
    if ((event == nlohmann::json::parse_event_t::object_start ||
         event == nlohmann::json::parse_event_t::array_start) &&
        depth >= kMaxRequestDepth) {
      throw ControlError("request is nested deeper than " + std::to_string(kMaxRequestDepth) +
                         " levels");
    }
    return true;
  };
  nlohmann::json request;
  try {
    request = nlohmann::json::parse(line, limit);
  } catch (const nlohmann::json::exception&) {
    throw ControlError("request is not valid JSON");
  }
  if (!request.is_object() || !request.contains("verb") || !request["verb"].is_string())
    throw ControlError("request needs a \"verb\" string");
  ParsedRequest r;
  r.verb = request["verb"].get<std::string>();
  if (auto it = request.find("args"); it != request.end()) r.args = std::move(*it);
  return r;
}

}  // namespace atelier
