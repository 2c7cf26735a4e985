#include "drivers/ayab/messages.h"

#include <cctype>
#include <cstdio>

#include "drivers/ayab/crc8.h"

namespace atelier::ayab {
namespace {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

void with_crc(Bytes& b) { b.push_back(crc8(b.data(), b.size())); }

std::string text_of(const Bytes& p, size_t from) {
  std::string s;
  for (size_t i = from; i < p.size() && p[i] != 0; ++i) s.push_back(static_cast<char>(p[i]));
  return s;
}

}  // namespace

int needle_count(MachineType m) { return m == MachineType::kh270 ? 112 : 200; }
int line_bytes(MachineType m) { return m == MachineType::kh270 ? 14 : 25; }
int end_of_line_offset(MachineType m) { return m == MachineType::kh270 ? 6 : 12; }

std::optional<MachineType> machine_from_name(const std::string& name) {
  if (name == "kh910" || name == "kh950i") return MachineType::kh910;
  if (name == "kh930" || name == "kh900" || name == "kh940" || name == "kh965i") return MachineType::kh930;
  if (name == "kh270") return MachineType::kh270;
  return std::nullopt;
}

std::string machine_name(MachineType m) {
  switch (m) {
    case MachineType::kh910: return "kh910";
    case MachineType::kh930: return "kh930";
    case MachineType::kh270: return "kh270";
  }
  return "unknown";
}

std::string machine_display_name(MachineType m) {
  const std::string n = machine_name(m);
  std::string out;
  for (char c : n.substr(0, 2)) out.push_back(static_cast<char>(std::toupper(static_cast<unsigned char>(c))));
  return out + "-" + n.substr(2);
}

std::string state_name(FsmState s) {
  switch (s) {
    case FsmState::wait_for_machine: return "wait-for-machine";
    case FsmState::init: return "init";
    case FsmState::ready: return "ready";
    case FsmState::knit: return "knitting";
    case FsmState::test: return "test";
    case FsmState::error: return "error";
  }
  return "state " + std::to_string(static_cast<int>(s));
}

std::string error_text(uint8_t code) {
  char hex[8];
  std::snprintf(hex, sizeof hex, "0x%02x", code);
  const char* what = nullptr;
  switch (code) {
    case err::success: what = "success"; break;
    case err::expected_longer_message: what = "message too short"; break;
    case err::unrecognized_msgid: what = "unknown message id"; break;
    case err::unexpected_msgid: what = "unexpected message id"; break;
    case err::checksum_error: what = "bad checksum"; break;
    case err::machine_type_invalid: what = "invalid machine type"; break;
    case err::needle_value_invalid: what = "invalid needle range"; break;
    case err::null_pointer_argument: what = "missing argument"; break;
    case err::argument_invalid: what = "invalid arguments"; break;
    case err::no_machine_type: what = "no machine type given"; break;
    case err::no_carriage: what = "no carriage detected"; break;
    case err::no_direction: what = "carriage direction unknown"; break;
    case err::no_beltshift: what = "belt shift unknown"; break;
    case err::machine_state_init: what = "wrong machine state: init"; break;
    case err::machine_state_ready: what = "wrong machine state: ready"; break;
    case err::machine_state_knit: what = "wrong machine state: knitting"; break;
    case err::machine_state_test: what = "wrong machine state: test"; break;
    case err::wrong_machine_state: what = "wrong machine state"; break;
    case err::warning: what = "firmware warning"; break;
    case err::recoverable_error: what = "recoverable firmware error"; break;
    case err::critical_error: what = "critical firmware error"; break;
    case err::fatal_error: what = "fatal firmware error"; break;
    case err::unspecified_failure: what = "unspecified firmware failure"; break;
    default:
      if (code <= 0x0F) what = "malformed message";
      else if (code <= 0x1F) what = "invalid arguments";
      else if (code <= 0x2F) what = "machine not initialised";
      else if (err::is_wrong_state(code)) what = "wrong machine state";
      else if (code >= 0xF0) what = "firmware error";
      else what = "unknown error";
  }
  return std::string(what) + " (" + hex + ")";
}

Bytes encode(const Message& m) {
  return std::visit(
      Overloaded{
          [](const ReqInfo&) { return Bytes{0x03}; },
          [](const CnfInfo& c) {
            Bytes b = {0xC3, c.api, c.fw_major, c.fw_minor, c.fw_patch};
            for (size_t i = 0; i < 17; ++i)
              b.push_back(i < c.suffix.size() && i < 16 ? static_cast<uint8_t>(c.suffix[i]) : 0);
            return b;
          },
          [](const ReqInit& r) {
            Bytes b = {0x05, static_cast<uint8_t>(r.machine)};
            with_crc(b);
            return b;
          },
          [](const CnfInit& c) { return Bytes{0xC5, c.error}; },
          [](const IndState& s) {
            return Bytes{0x84,
                         s.error,
                         static_cast<uint8_t>(s.state),
                         static_cast<uint8_t>(s.hall_left >> 8),
                         static_cast<uint8_t>(s.hall_left & 0xFF),
                         static_cast<uint8_t>(s.hall_right >> 8),
                         static_cast<uint8_t>(s.hall_right & 0xFF),
                         static_cast<uint8_t>(s.carriage),
                         s.position,
                         static_cast<uint8_t>(s.direction)};
          },
          [](const ReqStart& r) {
            Bytes b = {0x01, r.start_needle, r.stop_needle,
                       static_cast<uint8_t>((r.continuous_reporting ? 1 : 0) | (r.beeper ? 2 : 0))};
            with_crc(b);
            return b;
          },
          [](const CnfStart& c) { return Bytes{0xC1, c.error}; },
          [](const ReqLine& r) { return Bytes{0x82, r.line, r.error}; },
          [](const CnfLine& c) {
            Bytes b;
            b.reserve(5 + c.needles.size());
            for (uint8_t v : {uint8_t{0x42}, c.line, c.colour, uint8_t(c.last_line ? 1 : 0)}) b.push_back(v);
            for (uint8_t v : c.needles) b.push_back(v);
            with_crc(b);
            return b;
          },
          [](const ReqTest&) { return Bytes{0x04}; },
          [](const CnfTest& c) { return Bytes{0xC4, c.error}; },
          [](const Debug& d) {
            Bytes b = {0x9F};
            for (char ch : d.text) b.push_back(static_cast<uint8_t>(ch));
            return b;
          },
          [](const TestRes& t) {
            Bytes b = {0xEE};
            for (char ch : t.text) b.push_back(static_cast<uint8_t>(ch));
            return b;
          },
      },
      m);
}

DecodeResult decode(const Bytes& p, int line_bytes) {
  if (p.empty()) return {std::nullopt, err::too_short};
  auto need = [&](size_t n) { return p.size() >= n; };
  auto crc_ok = [&](size_t n) { return crc8(p.data(), n - 1) == p[n - 1]; };
  switch (p[0]) {
    case 0x03: return {ReqInfo{}, 0};
    case 0xC3: {
      if (!need(5)) return {std::nullopt, err::too_short};
      return {CnfInfo{p[1], p[2], p[3], p[4], text_of(p, 5)}, 0};
    }
    case 0x05: {
      if (!need(3)) return {std::nullopt, err::too_short};
      if (!crc_ok(3)) return {std::nullopt, err::bad_crc};
      return {ReqInit{static_cast<MachineType>(p[1])}, 0};
    }
    case 0xC5:
      if (!need(2)) return {std::nullopt, err::too_short};
      return {CnfInit{p[1]}, 0};
    case 0x84: {
      if (!need(10)) return {std::nullopt, err::too_short};
      IndState s;
      s.error = p[1];
      s.state = static_cast<FsmState>(p[2]);
      s.hall_left = static_cast<uint16_t>(p[3] << 8 | p[4]);
      s.hall_right = static_cast<uint16_t>(p[5] << 8 | p[6]);
      s.carriage = static_cast<Carriage>(p[7]);
      s.position = p[8];
      s.direction = static_cast<Direction>(p[9]);
      return {s, 0};
    }
    case 0x01: {
      if (!need(5)) return {std::nullopt, err::too_short};
      if (!crc_ok(5)) return {std::nullopt, err::bad_crc};
      return {ReqStart{p[1], p[2], (p[3] & 1) != 0, (p[3] & 2) != 0}, 0};
    }
    case 0xC1:
      if (!need(2)) return {std::nullopt, err::too_short};
      return {CnfStart{p[1]}, 0};
    case 0x82:
      if (!need(3)) return {std::nullopt, err::too_short};
      return {ReqLine{p[1], p[2]}, 0};
    case 0x42: {
      const size_t n = 4 + static_cast<size_t>(line_bytes) + 1;
      if (!need(n)) return {std::nullopt, err::too_short};
      if (!crc_ok(n)) return {std::nullopt, err::bad_crc};
      CnfLine c;
      c.line = p[1];
      c.colour = p[2];
      c.last_line = (p[3] & 1) != 0;
      c.needles.assign(p.begin() + 4, p.begin() + 4 + line_bytes);
      return {c, 0};
    }
    case 0x04: return {ReqTest{}, 0};
    case 0xC4:
      if (!need(2)) return {std::nullopt, err::too_short};
      return {CnfTest{p[1]}, 0};
    case 0x9F: return {Debug{text_of(p, 1)}, 0};
    case 0xEE: return {TestRes{text_of(p, 1)}, 0};
  }
  return {std::nullopt, err::bad_id};
}

std::string describe(const Message& m) {
  return std::visit(
      Overloaded{
          [](const ReqInfo&) -> std::string { return "reqInfo"; },
          [](const CnfInfo& c) -> std::string {
            return "cnfInfo(api " + std::to_string(c.api) + ", fw " + std::to_string(c.fw_major) +
                   "." + std::to_string(c.fw_minor) + "." + std::to_string(c.fw_patch) + ")";
          },
          [](const ReqInit& r) -> std::string { return "reqInit(" + machine_name(r.machine) + ")"; },
          [](const CnfInit& c) -> std::string { return "cnfInit(" + error_text(c.error) + ")"; },
          [](const IndState& s) -> std::string {
            return "indState(error " + std::to_string(s.error) + ", state " +
                   std::to_string(static_cast<int>(s.state)) + ")";
          },
          [](const ReqStart& r) -> std::string {
            return "reqStart(" + std::to_string(r.start_needle) + ".." + std::to_string(r.stop_needle) + ")";
          },
          [](const CnfStart& c) -> std::string { return "cnfStart(" + error_text(c.error) + ")"; },
          [](const ReqLine& r) -> std::string { return "reqLine(" + std::to_string(r.line) + ")"; },
          [](const CnfLine& c) -> std::string {
            return "cnfLine(" + std::to_string(c.line) + (c.last_line ? ", last" : "") + ")";
          },
          [](const ReqTest&) -> std::string { return "reqTest"; },
          [](const CnfTest& c) -> std::string { return "cnfTest(" + error_text(c.error) + ")"; },
          [](const Debug& d) -> std::string { return "debug(" + d.text + ")"; },
          [](const TestRes& t) -> std::string { return "testRes(" + t.text + ")"; },
      },
      m);
}

bool needle_selected(const Bytes& data, int needle) {
  const size_t byte = static_cast<size_t>(needle) >> 3;
  return byte < data.size() && (data[byte] >> (needle & 7)) & 1;
}

void select_needle(Bytes& data, int needle, bool on) {
  const size_t byte = static_cast<size_t>(needle) >> 3;
  if (byte >= data.size()) data.resize(byte + 1, 0);
  if (on) data[byte] = static_cast<uint8_t>(data[byte] | (1u << (needle & 7)));
  else data[byte] = static_cast<uint8_t>(data[byte] & ~(1u << (needle & 7)));
}

}  // namespace atelier::ayab
