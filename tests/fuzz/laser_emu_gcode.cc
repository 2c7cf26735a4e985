// G-code into the laser emulator, two ways: each line, filtered as GRBL's protocol.c filters it
// (comments, spaces and control characters dropped, upper case, at most 79 characters), through
// the parser (execute_gcode_line) with one parser state for the whole input; and the raw bytes,
// one line at a time, into the controller model, with the clock moving on so that motion runs,
// real-time bytes act and replies leave.
#include <algorithm>
#include <cctype>
#include <string>
#include <string_view>

#include "tests/fuzz/fuzz_targets.h"
#include "tools/laser_emu/controller.h"
#include "tools/laser_emu/gcode.h"
#include "tools/laser_emu/record.h"
#include "tools/laser_emu/settings.h"

namespace {

namespace emu = atelier::laser_emu;

void run_parser(std::string_view input) {
  const emu::Settings settings(400, 400);
  emu::GcState state;
  while (!input.empty()) {
    const size_t nl = input.find_first_of("\r\n");
    const std::string_view raw = input.substr(0, nl);
    input = nl == std::string_view::npos ? std::string_view() : input.substr(nl + 1);
    std::string line;
    bool paren = false;
    for (char c : raw) {
      if (paren) {
        paren = c != ')';
      } else if (c == '(') {
        paren = true;
      } else if (c == ';') {
        break;
      } else if (c > ' ' && c < 0x7f) {
        line += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
      }
    }
    if (line.empty() || line.size() > 79 || line[0] == '$') continue;
    (void)emu::execute_gcode_line(line, state, settings);
  }
}

void run_controller(std::string_view input) {
  emu::Record record;
  emu::ControllerOptions options;
  options.time_scale = 0.01;  // motion and dwells a hundred times faster
  emu::Controller controller(options, record, 0);
  int64_t now = 0;
  while (!input.empty()) {
    const size_t nl = input.find('\n');
    const size_t n = nl == std::string_view::npos ? input.size() : nl + 1;
    controller.host_write(input.substr(0, n), now);
    input.remove_prefix(n);
    now += 20000;  // us
    controller.advance_to(now);
    (void)controller.take_output();
  }
  for (int i = 0; i < 200; ++i) {  // let queued motion and replies finish (bounded)
    auto next = controller.next_event_us();
    if (!next) break;
    now = std::max(now, *next);
    controller.advance_to(now);
    (void)controller.take_output();
  }
  (void)controller.snapshot();
}

}  // namespace

int fuzz_laser_emu_gcode(const uint8_t* data, size_t size) {
  if (size > atelier::fuzz::kMaxFuzzInput) return 0;
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  run_parser(input);
  run_controller(input);
  return 0;
}
