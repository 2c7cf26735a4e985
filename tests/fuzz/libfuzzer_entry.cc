// libFuzzer's entry point for one fuzz target: the build compiles this file once per target
// with ATELIER_FUZZ_ENTRY set to the target's function (tests/fuzz/CMakeLists.txt).
#include "tests/fuzz/fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return ATELIER_FUZZ_ENTRY(data, size);
}
