#include "drivers/usb_id.h"

#include <cctype>
#include <cstdio>
#include <stdexcept>

namespace atelier {
namespace {

[[noreturn]] void bad(const std::string& text, const std::string& why) {
  throw std::invalid_argument("bad USB id \"" + text + "\": " + why +
                              " (expected vendor:product[:serial] in hex, e.g. 2341:0043)");
}

uint16_t parse_hex16(const std::string& text, const std::string& field, const char* what) {
  if (field.empty()) bad(text, std::string(what) + " is empty");
  if (field.size() > 4) bad(text, std::string(what) + " \"" + field + "\" has more than 4 hex digits");
  unsigned value = 0;
  for (char c : field) {
    if (!std::isxdigit(static_cast<unsigned char>(c)))
      bad(text, std::string(what) + " \"" + field + "\" is not hexadecimal");
    const int digit = std::isdigit(static_cast<unsigned char>(c))
                          ? c - '0'
                          : std::tolower(static_cast<unsigned char>(c)) - 'a' + 10;
    value = value * 16 + static_cast<unsigned>(digit);
  }
  return static_cast<uint16_t>(value);
}

}  // namespace

UsbId parse_usb_id(const std::string& text) {
  const auto first = text.find(':');
  if (first == std::string::npos) bad(text, "no ':' between vendor and product");
  const auto second = text.find(':', first + 1);
  UsbId id;
  id.vendor = parse_hex16(text, text.substr(0, first), "vendor id");
  id.product = parse_hex16(text, text.substr(first + 1, second == std::string::npos
                                                            ? std::string::npos
                                                            : second - first - 1),
                           "product id");
  if (second != std::string::npos) {
    id.serial = text.substr(second + 1);
    if (id.serial.empty()) bad(text, "serial number after the second ':' is empty");
    for (char c : id.serial)
      if (std::isspace(static_cast<unsigned char>(c)) || std::iscntrl(static_cast<unsigned char>(c)))
        bad(text, "serial number contains whitespace or control characters");
  }
  return id;
}

std::string to_string(const UsbId& id) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%04x:%04x", id.vendor, id.product);
  std::string out = buf;
  if (!id.serial.empty()) out += ":" + id.serial;
  return out;
}

bool usb_id_matches(const UsbId& wanted, const UsbId& device) {
  return wanted.vendor == device.vendor && wanted.product == device.product &&
         (wanted.serial.empty() || wanted.serial == device.serial);
}

}  // namespace atelier
