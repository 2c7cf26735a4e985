// daemon/control_request: parsing one request line; and the control server answering a line a
// fuzzer found (JSON nested 400000 deep) instead of overflowing its stack.
#include "daemon/control_request.h"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <string>

#include "daemon/control_server.h"

namespace fs = std::filesystem;

namespace atelier {
namespace {

std::string error_of(const std::string& line) {
  try {
    parse_request(line);
  } catch (const ControlError& e) {
    return e.what();
  }
  return "";
}

std::string nested_args(int depth) {
  return R"({"verb":"list","args":)" + std::string(depth, '[') + std::string(depth, ']') + "}";
}

TEST(ParseRequest, ReadsVerbAndArgs) {
  ParsedRequest r = parse_request(R"({"verb":"list","args":{"state":"failed","ids":[[1,2],[3]]}})");
  EXPECT_EQ(r.verb, "list");
  EXPECT_EQ(r.args["state"], "failed");
  EXPECT_EQ(r.args["ids"][1][0], 3);
  EXPECT_EQ(parse_request(R"({"verb":"status"})").args, nlohmann::json::object());
}

TEST(ParseRequest, RefusesWhatIsNoRequest) {
  EXPECT_EQ(error_of("{\"verb\":"), "request is not valid JSON");
  EXPECT_EQ(error_of("[1]"), "request needs a \"verb\" string");
  EXPECT_EQ(error_of(R"({"verb":5})"), "request needs a \"verb\" string");
  EXPECT_EQ(error_of(R"({"args":{}})"), "request needs a \"verb\" string");
}

TEST(ParseRequest, RefusesDeepNestingAndKeepsWhatTheProtocolUses) {
  EXPECT_EQ(error_of(nested_args(400000)), "request is nested deeper than 32 levels");
  EXPECT_EQ(error_of(nested_args(kMaxRequestDepth)), "request is nested deeper than 32 levels");
  EXPECT_EQ(parse_request(nested_args(kMaxRequestDepth - 1)).verb, "list");
}

class ControlServerLines : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("atelier-ctl-" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Sends `line` + "\n" on a new connection; the reply line, parsed.
  nlohmann::json send(const std::string& line) {
    int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::strncpy(addr.sun_path, socket_path().c_str(), sizeof addr.sun_path - 1);
    EXPECT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
    timeval tv{30, 0};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    const std::string out = line + "\n";
    for (size_t off = 0; off < out.size();) {
      ssize_t n = ::write(fd, out.data() + off, out.size() - off);
      if (n <= 0) break;
      off += static_cast<size_t>(n);
    }
    std::string reply;
    char c;
    while (::read(fd, &c, 1) == 1 && c != '\n') reply.push_back(c);
    ::close(fd);
    return reply.empty() ? nlohmann::json() : nlohmann::json::parse(reply);
  }
  fs::path socket_path() const { return dir_ / "control.sock"; }

  fs::path dir_;
};

TEST_F(ControlServerLines, ADeeplyNestedRequestIsRefusedAndTheServerGoesOn) {
  ControlServer server(socket_path(), "", [](ControlRequest& request) {
    return nlohmann::json(request.verb);
  });
  server.start();
  const nlohmann::json refused = send(nested_args(400000));  // 800 KB, under the 1 MB line cap
  EXPECT_EQ(refused, (nlohmann::json{{"ok", false}, {"error", "request is nested deeper than 32 levels"}}));
  EXPECT_EQ(send(R"({"verb":"status"})"), (nlohmann::json{{"ok", true}, {"result", "status"}}));
  server.stop();
}

}  // namespace
}  // namespace atelier
