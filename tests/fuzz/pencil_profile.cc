// A pencil profile file's text through the strict reader (profile_from_toml).
#include <string_view>

#include "base/error.h"
#include "convert/sketch/pencil_profile_file.h"
#include "tests/fuzz/fuzz_targets.h"

int fuzz_pencil_profile(const uint8_t* data, size_t size) {
  if (size > atelier::fuzz::kMaxFuzzInput) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    atelier::profile_from_toml(text, "pencil.toml");
  } catch (const atelier::BadInput&) {
  }
  return 0;
}
