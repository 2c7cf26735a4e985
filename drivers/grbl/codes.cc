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

// Index = code: what happened, in words an operator acts on, and what to do next. Written
// from GRBL 1.1h's limits.c / protocol.c behaviour, not its csv: the csv calls a soft-limit
// alarm "safely unlocked", but unlocking a job that does not fit only moves the problem.
constexpr std::array<std::string_view, 11> kAdvice = {
    "",
    "hard limit: a limit switch was hit, so GRBL stopped the head dead and its position is likely lost; "
    "see what hit the switch, check the machine, then home it ($H)",
    "soft limit: a move would have left the machine's travel ($130/$131), so GRBL stopped before it; the "
    "position was kept, but the job does not fit where it was placed: check the placement (start from) "
    "and the work area, then home the machine ($H) before the next job",
    "abort during cycle: a reset stopped the head while it moved, so its position may be lost; home the "
    "machine ($H) before the next job (or unlock it with $X if it has no homing switches)",
    "probe fail: the probe was not in its expected state before the probe cycle; check the probe and its "
    "wiring, then unlock ($X)",
    "probe fail: the probe did not touch within the programmed travel; check the probe and the work, then "
    "unlock ($X)",
    "homing fail: the homing cycle was reset; home the machine again ($H)",
    "homing fail: the safety door was opened during homing; close it, then home the machine again ($H)",
    "homing fail: the pull-off did not clear the limit switch; check the switch and $27 (pull-off), then "
    "home again ($H)",
    "homing fail: no limit switch was found within the search distance; check the switches, their wiring "
    "and $130/$131 (travel), then home again ($H)",
    "homing fail: the second limit switch of the auto-squared axis was not found; check it, then home again "
    "($H)",
};

}  // namespace

std::string alarm_advice(int code) {
  if (code < 1 || code >= static_cast<int>(kAdvice.size()))
    return "unknown alarm code: check the machine, then home it ($H) or unlock it ($X)";
  return std::string(kAdvice[code]);
}

std::string error_meaning(int code) {
  if (code < 1 || code >= static_cast<int>(kErrors.size()) || kErrors[code].empty()) return "unknown error code";
  return std::string(kErrors[code]);
}

std::string alarm_meaning(int code) {
  if (code < 1 || code >= static_cast<int>(kAlarms.size())) return "unknown alarm code";
  return std::string(kAlarms[code]);
}

}  // namespace atelier::grbl
