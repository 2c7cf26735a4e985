#include "daemon/web/http_reply.h"

#include <httplib.h>

namespace atelier::web {

void reply_json(httplib::Response& res, int status, const nlohmann::json& body) {
  res.status = status;
  res.set_header("Cache-Control", "no-store");  // jobs change: never a stale list
  // Replacement characters for invalid UTF-8 in a job's name or reason, never an exception.
  res.set_content(body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), "application/json");
}

void json_error(httplib::Response& res, int status, const std::string& message) {
  reply_json(res, status, {{"error", message}});
}

}  // namespace atelier::web
