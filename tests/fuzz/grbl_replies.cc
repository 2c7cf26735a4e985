// Lines from a GRBL controller, split as the session splits them ("\n", "\r" dropped), through
// every parser the driver applies to them.
#include <array>
#include <string_view>

#include "drivers/grbl/messages.h"
#include "tests/fuzz/fuzz_targets.h"

int fuzz_grbl_replies(const uint8_t* data, size_t size) {
  if (size > atelier::fuzz::kMaxFuzzInput) return 0;
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  std::array<double, 3> wco{0, 0, 0};
  while (!rest.empty()) {
    size_t nl = rest.find('\n');
    std::string_view line = rest.substr(0, nl);
    rest = nl == std::string_view::npos ? std::string_view() : rest.substr(nl + 1);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    (void)atelier::grbl::classify(line);
    if (auto status = atelier::grbl::parse_status(line)) {
      if (status->wco) wco = *status->wco;
      atelier::grbl::apply_wco(*status, wco);
    }
    (void)atelier::grbl::parse_opt(line);
    (void)atelier::grbl::parse_setting(line);
  }
  return 0;
}
