// [web] listen and allow_from: who reaches the page is what the administrator wrote.
#include "daemon/web/address_filter.h"

#include <gtest/gtest.h>

#include "base/error.h"

namespace atelier::web {
namespace {

TEST(ListenAddress, ParsesIpv4Ipv6AndLocalhost) {
  auto a = parse_listen_address("127.0.0.1:8631");
  EXPECT_EQ(a.host, "127.0.0.1");
  EXPECT_EQ(a.port, 8631);
  a = parse_listen_address("[::1]:9000");
  EXPECT_EQ(a.host, "::1");
  EXPECT_EQ(a.port, 9000);
  EXPECT_EQ(parse_listen_address("localhost:80").host, "127.0.0.1");
  EXPECT_EQ(parse_listen_address("0.0.0.0:8631").host, "0.0.0.0");
}

TEST(ListenAddress, RefusesWhatIsNotHostPortWithAReason) {
  for (const char* bad : {"8631", "127.0.0.1", "127.0.0.1:", "127.0.0.1:0", "127.0.0.1:70000", "::1:8631",
                          "[::1]8631", "printer.local:8631", "127.0.0.1:86x1"}) {
    try {
      parse_listen_address(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const BadInput& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

TEST(AddressFilter, LocalhostAllowsLoopbackOnly) {
  AddressFilter f({"localhost"});
  EXPECT_TRUE(f.allows("127.0.0.1"));
  EXPECT_TRUE(f.allows("127.8.9.10"));
  EXPECT_TRUE(f.allows("::1"));
  EXPECT_TRUE(f.allows("::ffff:127.0.0.1"));  // an IPv4 peer on an IPv6 socket
  EXPECT_FALSE(f.allows("192.168.1.7"));
  EXPECT_FALSE(f.allows("::2"));
  EXPECT_FALSE(f.allows("not an address"));
}

TEST(AddressFilter, CidrBlocksMatchTheirPrefixOnly) {
  AddressFilter f({"192.168.1.0/24", "10.0.0.0/9", "fd00::/8", "172.16.5.5"});
  EXPECT_TRUE(f.allows("192.168.1.200"));
  EXPECT_FALSE(f.allows("192.168.2.1"));
  EXPECT_TRUE(f.allows("10.127.255.255"));
  EXPECT_FALSE(f.allows("10.128.0.0"));  // the 9th bit differs
  EXPECT_TRUE(f.allows("fd12:3456::1"));
  EXPECT_FALSE(f.allows("fe80::1"));
  EXPECT_TRUE(f.allows("172.16.5.5"));
  EXPECT_FALSE(f.allows("172.16.5.6"));
  EXPECT_FALSE(f.allows("127.0.0.1"));  // loopback is not implied
  EXPECT_TRUE(f.allows("::ffff:192.168.1.3"));
}

TEST(AddressFilter, AnyAllowsEveryone) {
  AddressFilter f({"any"});
  EXPECT_TRUE(f.allows("203.0.113.9"));
  EXPECT_TRUE(f.allows("2001:db8::1"));
}

TEST(AddressFilter, RefusesBadEntriesNamingThem) {
  for (const char* bad : {"192.168.1.0/33", "fd00::/129", "lan", "192.168.1/24", "10.0.0.0/"}) {
    try {
      AddressFilter f({bad});
      ADD_FAILURE() << bad << " was accepted";
    } catch (const BadInput& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

TEST(HostAllowed, AddressesLocalhostAndTheBoxsNamesOnly) {
  const std::vector<std::string> names = {"workshop", "workshop.local", "atelier.example.org"};
  for (const char* ok : {"127.0.0.1:8631", "192.168.1.20:8631", "[::1]:8631", "localhost:8631", "localhost",
                         "Workshop.LOCAL:8631", "atelier.example.org", "atelier.example.org.:80", ""})
    EXPECT_TRUE(host_allowed(ok, names)) << ok;
  for (const char* bad : {"evil.example:8631", "workshop.evil.example", "127.0.0.1.evil.example:8631",
                          "localhost.evil.example", "example.org"})
    EXPECT_FALSE(host_allowed(bad, names)) << bad;
}

TEST(AddressFilter, DefaultIsLocalhostOnLoopbackAndAnyOtherwise) {
  EXPECT_EQ(default_allow_from("127.0.0.1"), std::vector<std::string>{"localhost"});
  EXPECT_EQ(default_allow_from("::1"), std::vector<std::string>{"localhost"});
  EXPECT_EQ(default_allow_from("0.0.0.0"), std::vector<std::string>{"any"});
  EXPECT_EQ(default_allow_from("192.168.1.20"), std::vector<std::string>{"any"});
}

}  // namespace
}  // namespace atelier::web
