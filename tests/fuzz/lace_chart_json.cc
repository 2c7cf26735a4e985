// A lace chart.json as the knitting-machine device and `start_chart` read it.
#include <stdexcept>
#include <string>

#include "convert/lace/lace_chart_json.h"
#include "tests/fuzz/fuzz_targets.h"

int fuzz_lace_chart_json(const uint8_t* data, size_t size) {
  if (size > atelier::fuzz::kMaxFuzzInput) return 0;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    atelier::LaceChartFile file = atelier::lace_chart_from_json_text(text, "chart.json");
    // What is read back must write out again (the device re-serialises nothing, but a chart
    // that reads must be a valid chart).
    (void)atelier::lace_chart_to_json(file).dump();
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
