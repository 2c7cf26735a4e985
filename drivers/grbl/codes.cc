#include "drivers/grbl/codes.h"

#include <array>
#include <string_view>

namespace atelier::grbl {
namespace {

// Index = code. Short name, then GRBL's description (the csv's third column), lower-cased
// and without its final period so it reads inside a sentence.
constexpr std::array<std::string_view, 39> kErrors = {
    "",
    "expected command letter: G-code words consist of a letter and a value; the letter was not found",
    "bad number format: missing the expected G-code word value or the numeric value format is not valid",
    "invalid statement: GRBL '$' system command was not recognized or supported",
    "value < 0: negative value received for an expected positive value",
    "setting disabled: homing cycle failure; homing is not enabled via settings",
    "value < 3 usec: minimum step pulse time must be greater than 3 usec",
    "EEPROM read fail: an EEPROM read failed; auto-restoring affected EEPROM to default values",
    "not idle: GRBL '$' command cannot be used unless GRBL is idle",
    "G-code lock: G-code commands are locked out during alarm or jog state",
    "homing not enabled: soft limits cannot be enabled without homing also enabled",
    "line overflow: max characters per line exceeded; the line was not executed",
    "step rate > 30kHz: the '$' setting value causes the step rate to exceed the maximum supported",
    "check door: safety door detected as opened and door state initiated",
    "line length exceeded: build info or startup line exceeded EEPROM line length limit; line not stored",
    "travel exceeded: jog target exceeds machine travel; jog command has been ignored",
    "invalid jog command: jog command has no '=' or contains prohibited G-code",
    "setting disabled: laser mode requires PWM output",
    "",
    "",
    "unsupported command: unsupported or invalid G-code command found in block",
    "modal group violation: more than one G-code command from the same modal group found in block",
    "undefined feed rate: feed rate has not yet been set or is undefined",
    "integer required: G-code command in block requires an integer value",
    "axis words conflict: more than one G-code command that requires axis words found in block",
    "repeated word: repeated G-code word found in block",
    "no axis words: no axis words found in block for G-code command or current modal state which requires them",
    "invalid line number: line number value is invalid",
    "missing value: G-code command is missing a required value word",
    "unsupported coordinate system: G59.x work coordinate systems are not supported",
    "invalid G53: G53 only allowed with G0 and G1 motion modes",
    "unused axis words: axis words found in block when no command or current modal state uses them",
    "arc without axis words: G2 and G3 arcs require at least one in-plane axis word",
    "invalid target: motion command target is invalid",
    "invalid arc radius: arc radius value is invalid",
    "arc without offsets: G2 and G3 arcs require at least one in-plane offset word",
    "unused value words: unused value words found in block",
    "invalid tool length axis: G43.1 dynamic tool length offset is not assigned to configured tool length axis",
    "tool number too large: tool number greater than max supported value",
};

constexpr std::array<std::string_view, 11> kAlarms = {
    "",
    "hard limit: hard limit has been triggered; machine position is likely lost due to sudden halt, "
    "re-homing is highly recommended",
    "soft limit: G-code motion target exceeds machine travel; machine position retained, alarm may be "
    "safely unlocked",
    "abort during cycle: reset while in motion; machine position is likely lost due to sudden halt, "
    "re-homing is highly recommended",
    "probe fail: probe is not in the expected initial state before starting probe cycle",
    "probe fail: probe did not contact the workpiece within the programmed travel",
    "homing fail: the active homing cycle was reset",
    "homing fail: safety door was opened during homing cycle",
    "homing fail: pull off travel failed to clear limit switch",
    "homing fail: could not find limit switch within search distances",
    "homing fail: could not find second limit switch for auto squared axis within search distances",
};

}  // namespace

std::string error_meaning(int code) {
  if (code < 1 || code >= static_cast<int>(kErrors.size()) || kErrors[code].empty()) return "unknown error code";
  return std::string(kErrors[code]);
}

std::string alarm_meaning(int code) {
  if (code < 1 || code >= static_cast<int>(kAlarms.size())) return "unknown alarm code";
  return std::string(kAlarms[code]);
}

}  // namespace atelier::grbl
