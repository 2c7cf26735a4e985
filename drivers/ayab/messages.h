// The AYAB serial API v6 messages (../shared/protocols/ayab-v6.md): byte layouts for both
// directions, so the host driver and the firmware emulator share one definition.
// Messages carrying a CRC (reqInit, reqStart, cnfLine) get it appended by encode() and
// checked by decode(). Pure, thread-safe.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "drivers/ayab/slip.h"

namespace atelier::ayab {

constexpr uint8_t kApiVersion = 6;

enum class MsgId : uint8_t {
  reqStart = 0x01, cnfStart = 0xC1,
  reqLine = 0x82, cnfLine = 0x42,
  reqInfo = 0x03, cnfInfo = 0xC3,
  reqTest = 0x04, cnfTest = 0xC4,
  reqInit = 0x05, cnfInit = 0xC5,
  indState = 0x84,
  debug = 0x9F,
  testRes = 0xEE,
};

enum class MachineType : uint8_t { kh910 = 0, kh930 = 1, kh270 = 2 };
int needle_count(MachineType m);        // 200, 200, 112
int line_bytes(MachineType m);          // 25, 25, 14
int end_of_line_offset(MachineType m);  // needles past the working range before reqLine: 12 / 6
std::optional<MachineType> machine_from_name(const std::string& name);  // "kh910", "kh930", "kh270"
std::string machine_name(MachineType m);
// "KH-930": as printed on the machine, for messages to users.
std::string machine_display_name(MachineType m);

enum class FsmState : uint8_t { wait_for_machine = 0, init = 1, ready = 2, knit = 3, test = 4, error = 5 };
std::string state_name(FsmState s);  // "wait-for-machine", "init", "ready", "knitting", "test", "error", "state N"
enum class Carriage : uint8_t { knit = 0, lace = 1, garter = 2, none = 0xFF };
enum class Direction : uint8_t { left = 0, right = 1, unknown = 0xFF };

// Error codes of the firmware: the ErrorCode table of AYAB firmware 1.0.0 (src/ayab/fsm.h).
// Firmware 1.0 itself only ever sends 0x01, 0x04, 0x11, 0x12, 0x20, 0xEF (and 0xFF in the
// indStates of its hardware-test mode); the others are listed so that any code reads in words.
namespace err {
constexpr uint8_t success = 0x00;
// 0x01..0x04: message not understood
constexpr uint8_t expected_longer_message = 0x01;
constexpr uint8_t unrecognized_msgid = 0x02;
constexpr uint8_t unexpected_msgid = 0x03;
constexpr uint8_t checksum_error = 0x04;
// 0x10..0x13: invalid arguments
constexpr uint8_t machine_type_invalid = 0x10;
constexpr uint8_t needle_value_invalid = 0x11;  // reqStart: not start < stop < needle count
constexpr uint8_t null_pointer_argument = 0x12;
constexpr uint8_t argument_invalid = 0x13;
constexpr uint8_t arguments_incompatible = 0x13;
// 0x20..0x23: device not initialised
constexpr uint8_t no_machine_type = 0x20;  // reqInit with machine byte 0xFF
constexpr uint8_t no_carriage = 0x21;
constexpr uint8_t no_direction = 0x22;
constexpr uint8_t no_beltshift = 0x23;
// 0xE0..0xEF: machine in the wrong state
constexpr uint8_t machine_state_init = 0xE0;
constexpr uint8_t machine_state_ready = 0xE1;
constexpr uint8_t machine_state_knit = 0xE2;
constexpr uint8_t machine_state_test = 0xE3;
// What firmware 1.0 answers reqInit outside wait-for-machine, reqStart outside ready and
// reqTest while knitting (Knitter::initMachine/startKnitting, Tester::startTest): one code
// for every wrong state, which it does not name.
constexpr uint8_t wrong_machine_state = 0xEF;
// 0xF0..0xFF: generic
constexpr uint8_t warning = 0xF0;
constexpr uint8_t recoverable_error = 0xF1;
constexpr uint8_t critical_error = 0xF2;
constexpr uint8_t fatal_error = 0xF3;
constexpr uint8_t unspecified_failure = 0xFF;

// Names the rest of atelier uses.
constexpr uint8_t too_short = expected_longer_message;
constexpr uint8_t bad_id = unrecognized_msgid;
constexpr uint8_t bad_crc = checksum_error;
constexpr uint8_t bad_argument = machine_type_invalid;  // first of 0x10..0x13
constexpr uint8_t bad_needles = needle_value_invalid;
constexpr uint8_t not_initialised = no_machine_type;    // first of 0x20..0x23
constexpr uint8_t wrong_state = machine_state_init;     // first of 0xE0..0xEF
constexpr uint8_t generic = warning;
// 0xE0..0xEF: the machine was in the wrong state for the request.
constexpr bool is_wrong_state(uint8_t code) { return code >= 0xE0 && code <= 0xEF; }
}  // namespace err
// "bad checksum (0x04)", "wrong machine state (0xef)", "wrong machine state: knitting (0xe2)":
// the firmware's meaning in plain words and the code in hex, for messages to users.
std::string error_text(uint8_t code);

struct ReqInfo {};
struct CnfInfo {
  uint8_t api = kApiVersion;
  uint8_t fw_major = 1, fw_minor = 0, fw_patch = 0;
  std::string suffix;  // up to 16 characters (17 bytes with the NUL)
};
struct ReqInit { MachineType machine = MachineType::kh930; };
struct CnfInit { uint8_t error = err::success; };
struct IndState {
  uint8_t error = err::success;  // 0 = ready
  FsmState state = FsmState::init;
  uint16_t hall_left = 0, hall_right = 0;
  Carriage carriage = Carriage::none;
  uint8_t position = 0;  // needle the carriage is at
  Direction direction = Direction::unknown;
};
struct ReqStart {
  uint8_t start_needle = 0, stop_needle = 199;
  bool continuous_reporting = false;
  bool beeper = true;
};
struct CnfStart { uint8_t error = err::success; };
struct ReqLine {
  uint8_t line = 0;  // line number modulo 256
  uint8_t error = err::success;
};
struct CnfLine {
  uint8_t line = 0;
  uint8_t colour = 0;
  bool last_line = false;
  Bytes needles;  // line_bytes(machine) bytes; needle i = bit (i & 7) of byte (i >> 3)
};
struct ReqTest {};
struct CnfTest { uint8_t error = err::success; };
// Text messages: the id and the characters, no terminating NUL (Com::sendMsg).
struct Debug { std::string text; };
struct TestRes { std::string text; };

using Message = std::variant<ReqInfo, CnfInfo, ReqInit, CnfInit, IndState, ReqStart, CnfStart,
                             ReqLine, CnfLine, ReqTest, CnfTest, Debug, TestRes>;

// The unframed message bytes (id first; CRC last where the message has one).
Bytes encode(const Message& m);

struct DecodeResult {
  std::optional<Message> message;
  uint8_t error = err::success;  // too_short, bad_id or bad_crc when message is empty
};
// `line_bytes` tells how much needle data a cnfLine carries (it is not in the message).
DecodeResult decode(const Bytes& packet, int line_bytes);

std::string describe(const Message& m);  // e.g. "reqLine(12)", for logs and errors

// Needle bitmap helpers: bit set = needle selected.
bool needle_selected(const Bytes& data, int needle);
void select_needle(Bytes& data, int needle, bool on);

}  // namespace atelier::ayab
