// The first bytes of an image file: the hand-written header parser and completeness check
// that run before any decoder (probe_header, check_complete).
#include <vector>

#include "convert/common/image_signature.h"
#include "tests/fuzz/fuzz_targets.h"

int fuzz_image_header(const uint8_t* data, size_t size) {
  if (size > atelier::fuzz::kMaxFuzzInput) return 0;
  const std::vector<unsigned char> bytes(data, data + size);
  atelier::MemoryBytes source(bytes);
  try {
    const atelier::ImageHeader header = atelier::probe_header(source);
    (void)atelier::check_complete(header.format, source);
  } catch (const atelier::SignatureError&) {
  }
  return 0;
}
