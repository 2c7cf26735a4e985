// Where the web server listens and whom it answers: the `[web] listen` address and the
// `[web] allow_from` list (docs/web.md). Pure: no sockets are opened here.
// Threading: AddressFilter is immutable once built; any thread may call allows().
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace atelier::web {

struct ListenAddress {
  std::string host;  // numeric, without brackets: "127.0.0.1", "::1", "0.0.0.0"
  int port = 0;      // 1..65535
};

// "127.0.0.1:8631", "0.0.0.0:8631", "[::1]:8631", "[::]:8631", "localhost:8631" (taken as
// 127.0.0.1). Throws BadInput saying what is wrong with `text`.
ListenAddress parse_listen_address(const std::string& text);

// 127.0.0.0/8 or ::1.
bool is_loopback_host(const std::string& host);

// Whether `host` (numeric, as ListenAddress::host) is an IPv6 address: "::", "::1", "fd00::7".
inline bool is_ipv6_host(const std::string& host) { return host.find(':') != std::string::npos; }

// What `allow_from` is when the configuration does not say: ["localhost"] for a loopback
// address, else ["any"] (a LAN address is meant to be reached from the LAN).
std::vector<std::string> default_allow_from(const std::string& host);

// Whether a request's Host header names this server: an address (any IP literal), "localhost",
// or one of `names` (the box's own names and [web] server_names), with or without a port,
// case-insensitively. A page of another site that made its own name point at this box (DNS
// rebinding) sends its own name, and is refused. An absent Host (HTTP/1.0) is allowed.
bool host_allowed(const std::string& host_header, const std::vector<std::string>& names);

class AddressFilter {
 public:
  // Entries: "any", "localhost" (127.0.0.0/8 and ::1), an address ("192.168.1.7", "fe80::1")
  // or a CIDR block ("192.168.1.0/24", "fd00::/8"). Throws BadInput naming a bad entry.
  explicit AddressFilter(const std::vector<std::string>& entries);

  // Whether a peer at `address` (numeric, as the server reports it; IPv4-mapped IPv6
  // "::ffff:a.b.c.d" counts as IPv4) may connect. An address that does not parse is refused.
  bool allows(const std::string& address) const;

 private:
  struct Block {
    bool v6 = false;
    std::array<uint8_t, 16> bytes{};
    int prefix = 0;  // bits that must match
  };
  std::vector<Block> blocks_;
  bool any_ = false;
};

}  // namespace atelier::web
