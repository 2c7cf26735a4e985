// A USB device identity as the configuration names it: `usb = "2341:0043"` or
// `usb = "2341:0043:75833353035351D0F1A1"` (vendor:product[:serial], vendor and product in
// hex as lsusb prints them). Pure value type; no I/O.
#pragma once

#include <cstdint>
#include <string>

namespace atelier {

struct UsbId {
  uint16_t vendor = 0;
  uint16_t product = 0;
  std::string serial;  // iSerialNumber string; empty = any serial

  bool operator==(const UsbId&) const = default;
};

// Parses "VVVV:PPPP" or "VVVV:PPPP:SERIAL". Vendor and product are 1-4 hex digits, either
// case; the serial is everything after the second colon, taken verbatim (it must not be
// empty or contain whitespace). Throws std::invalid_argument quoting the text on any error.
UsbId parse_usb_id(const std::string& text);

// "2341:0043" or "2341:0043:SERIAL" (lower-case hex, 4 digits), round-trips parse_usb_id.
std::string to_string(const UsbId& id);

// True when `device` is what `wanted` asks for: same vendor and product, and the same serial
// when `wanted` names one (exact, case-sensitive: serials are opaque strings).
bool usb_id_matches(const UsbId& wanted, const UsbId& device);

}  // namespace atelier
