// The unit's network sandbox follows [web]: nothing opened while it is off, only the
// listening family and allow_from's peers when it is on.
#include "daemon/web/sandbox_dropin.h"

#include <gtest/gtest.h>

namespace atelier::web {
namespace {

TEST(SandboxDropin, OffOpensNothing) {
  const std::string d = sandbox_dropin(WebConfig{}, "/etc/atelier/atelierd.toml");
  EXPECT_EQ(d.find("[Service]"), std::string::npos) << d;
  EXPECT_NE(d.find("/etc/atelier/atelierd.toml"), std::string::npos);
}

TEST(SandboxDropin, LoopbackIpv4AllowsInetFromLocalhostOnly) {
  WebConfig w;
  w.enabled = true;
  w.allow_from = {"localhost"};
  const std::string d = sandbox_dropin(w, "x.toml");
  EXPECT_NE(d.find("[Service]\n"), std::string::npos);
  EXPECT_NE(d.find("RestrictAddressFamilies=\nRestrictAddressFamilies=AF_UNIX AF_NETLINK AF_INET\n"),
            std::string::npos) << d;
  EXPECT_NE(d.find("IPAddressAllow=localhost\n"), std::string::npos) << d;
  EXPECT_EQ(d.find("AF_INET6"), std::string::npos);
}

TEST(SandboxDropin, LanIpv6WithBlocks) {
  WebConfig w;
  w.enabled = true;
  w.listen = "[::]:8631";
  w.host = "::";
  w.allow_from = {"192.168.1.0/24", "fd00::/8"};
  const std::string d = sandbox_dropin(w, "x.toml");
  EXPECT_NE(d.find("RestrictAddressFamilies=AF_UNIX AF_NETLINK AF_INET6\n"), std::string::npos) << d;
  EXPECT_NE(d.find("IPAddressAllow=192.168.1.0/24 fd00::/8\n"), std::string::npos) << d;
}

}  // namespace
}  // namespace atelier::web
