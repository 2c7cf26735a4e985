// The SVG reader on one drawing: read_svg as the cut kind calls it (0.1 mm tolerance).
#include "base/error.h"
#include "convert/common/svg_paths.h"
#include "tests/fuzz/fuzz_targets.h"
#include "tests/fuzz/memory_file.h"

int fuzz_svg_reader(const uint8_t* data, size_t size) {
  if (size > atelier::fuzz::kMaxFuzzInput) return 0;
  atelier::fuzz::MemoryFile file(data, size);
  try {
    atelier::read_svg(file.path(), 0.1);
  } catch (const atelier::BadInput&) {
  }
  return 0;
}
