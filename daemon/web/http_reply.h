// Answers of the web API: JSON bodies, and errors as {"error": message} (docs/web.md).
// Threading: stateless; any thread.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace httplib {
struct Response;
}

namespace atelier::web {

void reply_json(httplib::Response& res, int status, const nlohmann::json& body);
void json_error(httplib::Response& res, int status, const std::string& message);

}  // namespace atelier::web
