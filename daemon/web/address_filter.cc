#include "daemon/web/address_filter.h"

#include <arpa/inet.h>

#include <cctype>
#include <charconv>
#include <cstring>
#include <optional>

#include "base/error.h"

namespace atelier::web {
namespace {

struct Parsed {
  bool v6 = false;
  std::array<uint8_t, 16> bytes{};
};

// A numeric address; IPv4-mapped IPv6 is turned into IPv4, so "::ffff:127.0.0.1" and
// "127.0.0.1" match the same blocks.
std::optional<Parsed> parse_address(const std::string& text) {
  Parsed p;
  if (inet_pton(AF_INET, text.c_str(), p.bytes.data()) == 1) return p;
  if (inet_pton(AF_INET6, text.c_str(), p.bytes.data()) != 1) return std::nullopt;
  static constexpr uint8_t kMapped[12] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xff, 0xff};
  if (std::memcmp(p.bytes.data(), kMapped, 12) == 0) {
    std::memmove(p.bytes.data(), p.bytes.data() + 12, 4);
    std::memset(p.bytes.data() + 4, 0, 12);
    return p;
  }
  p.v6 = true;
  return p;
}

bool prefix_matches(const std::array<uint8_t, 16>& a, const std::array<uint8_t, 16>& b, int bits) {
  const int whole = bits / 8;
  if (std::memcmp(a.data(), b.data(), static_cast<size_t>(whole)) != 0) return false;
  const int rest = bits % 8;
  if (rest == 0) return true;
  const uint8_t mask = static_cast<uint8_t>(0xff << (8 - rest));
  return (a[static_cast<size_t>(whole)] & mask) == (b[static_cast<size_t>(whole)] & mask);
}

}  // namespace

ListenAddress parse_listen_address(const std::string& text) {
  const std::string usage = "listen '" + text + "': expected host:port, e.g. \"127.0.0.1:8631\", "
                            "\"0.0.0.0:8631\" or \"[::1]:8631\"";
  ListenAddress out;
  std::string port;
  if (!text.empty() && text.front() == '[') {
    const auto close = text.find(']');
    if (close == std::string::npos || close + 1 >= text.size() || text[close + 1] != ':') throw BadInput(usage);
    out.host = text.substr(1, close - 1);
    port = text.substr(close + 2);
  } else {
    const auto colon = text.rfind(':');
    if (colon == std::string::npos || text.find(':') != colon) throw BadInput(usage);
    out.host = text.substr(0, colon);
    port = text.substr(colon + 1);
  }
  if (out.host == "localhost") out.host = "127.0.0.1";
  if (!parse_address(out.host)) throw BadInput(usage + " (the host must be a numeric address)");
  int value = 0;
  auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), value);
  if (ec != std::errc() || end != port.data() + port.size() || value < 1 || value > 65535)
    throw BadInput("listen '" + text + "': the port must be a number from 1 to 65535");
  out.port = value;
  return out;
}

bool is_loopback_host(const std::string& host) {
  auto p = parse_address(host);
  if (!p) return false;
  if (!p->v6) return p->bytes[0] == 127;
  std::array<uint8_t, 16> one{};
  one[15] = 1;
  return p->bytes == one;
}

std::vector<std::string> default_allow_from(const std::string& host) {
  return {is_loopback_host(host) ? "localhost" : "any"};
}

bool host_allowed(const std::string& host_header, const std::vector<std::string>& names) {
  if (host_header.empty()) return true;
  std::string host = host_header;
  if (host.front() == '[') {
    host = host.substr(1, host.find(']') == std::string::npos ? std::string::npos : host.find(']') - 1);
  } else if (const auto colon = host.rfind(':'); colon != std::string::npos && host.find(':') == colon) {
    host = host.substr(0, colon);
  }
  for (char& c : host) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (!host.empty() && host.back() == '.') host.pop_back();  // "box.local." is "box.local"
  if (parse_address(host) || host == "localhost") return true;
  for (std::string name : names) {
    for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (host == name) return true;
  }
  return false;
}

AddressFilter::AddressFilter(const std::vector<std::string>& entries) {
  for (const std::string& entry : entries) {
    if (entry == "any") {
      any_ = true;
      continue;
    }
    if (entry == "localhost") {
      Block v4;
      v4.bytes[0] = 127;
      v4.prefix = 8;
      Block v6;
      v6.v6 = true;
      v6.bytes[15] = 1;
      v6.prefix = 128;
      blocks_.push_back(v4);
      blocks_.push_back(v6);
      continue;
    }
    const auto slash = entry.find('/');
    const std::string address = entry.substr(0, slash);
    auto parsed = parse_address(address);
    if (!parsed)
      throw BadInput("allow_from '" + entry + "': expected \"any\", \"localhost\", an address or a CIDR block "
                     "such as \"192.168.1.0/24\"");
    Block b;
    b.v6 = parsed->v6;
    b.bytes = parsed->bytes;
    const int max_bits = b.v6 ? 128 : 32;
    b.prefix = max_bits;
    if (slash != std::string::npos) {
      const std::string bits = entry.substr(slash + 1);
      int value = -1;
      auto [end, ec] = std::from_chars(bits.data(), bits.data() + bits.size(), value);
      if (ec != std::errc() || end != bits.data() + bits.size() || value < 0 || value > max_bits)
        throw BadInput("allow_from '" + entry + "': the prefix length must be 0 to " + std::to_string(max_bits));
      b.prefix = value;
    }
    blocks_.push_back(b);
  }
}

bool AddressFilter::allows(const std::string& address) const {
  if (any_) return true;
  auto p = parse_address(address);
  if (!p) return false;
  for (const Block& b : blocks_)
    if (b.v6 == p->v6 && prefix_matches(b.bytes, p->bytes, b.prefix)) return true;
  return false;
}

}  // namespace atelier::web
