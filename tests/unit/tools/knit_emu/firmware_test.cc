// The pure AYAB firmware 1.0.0 model (tools/knit_emu/firmware.h) driven by encoded messages on
// a simulated clock: the messages, states and error codes, and the faults it implements. Each
// expectation is what the firmware's source does (src/ayab/com.cpp, knitter.cpp, fsm.h at tag
// 1.0.0). The carriage, the knitter and the record: firmware_knitting_test.cc; the hardware test
// mode: firmware_test_mode_test.cc.
#include <gtest/gtest.h>

#include "drivers/ayab/crc8.h"
#include "tests/support/knit_emu_rig.h"

namespace atelier::knit_emu::testing {
namespace {

TEST(KnitEmuErrors, TheTableIsTheFirmwaresAndEachCodeReadsInWords) {
  // fsm.h ErrorCode: bad CRC is 0x04 (0x03 is an unexpected message id), wrong state 0xEF with
  // the per-state 0xE0..0xE3, reqStart's range 0x11, reqInit's missing machine 0x20.
  EXPECT_EQ(ab::err::checksum_error, 0x04);
  EXPECT_EQ(ab::err::bad_crc, 0x04);
  EXPECT_EQ(ab::err::unexpected_msgid, 0x03);
  EXPECT_EQ(ab::err::wrong_machine_state, 0xEF);
  EXPECT_EQ(ab::err::needle_value_invalid, 0x11);
  EXPECT_EQ(ab::err::no_machine_type, 0x20);
  const std::pair<uint8_t, std::string> table[] = {
      {0x00, "success (0x00)"},
      {0x01, "message too short (0x01)"},
      {0x02, "unknown message id (0x02)"},
      {0x03, "unexpected message id (0x03)"},
      {0x04, "bad checksum (0x04)"},
      {0x10, "invalid machine type (0x10)"},
      {0x11, "invalid needle range (0x11)"},
      {0x12, "missing argument (0x12)"},
      {0x13, "invalid arguments (0x13)"},
      {0x20, "no machine type given (0x20)"},
      {0x21, "no carriage detected (0x21)"},
      {0x22, "carriage direction unknown (0x22)"},
      {0x23, "belt shift unknown (0x23)"},
      {0xE0, "wrong machine state: init (0xe0)"},
      {0xE1, "wrong machine state: ready (0xe1)"},
      {0xE2, "wrong machine state: knitting (0xe2)"},
      {0xE3, "wrong machine state: test (0xe3)"},
      {0xEF, "wrong machine state (0xef)"},
      {0xF0, "firmware warning (0xf0)"},
      {0xF1, "recoverable firmware error (0xf1)"},
      {0xF2, "critical firmware error (0xf2)"},
      {0xF3, "fatal firmware error (0xf3)"},
      {0xFF, "unspecified firmware failure (0xff)"},
  };
  for (const auto& [code, text] : table) EXPECT_EQ(ab::error_text(code), text);
  EXPECT_EQ(ab::error_text(0xE7), "wrong machine state (0xe7)");
  EXPECT_EQ(ab::error_text(0x07), "malformed message (0x07)");
  for (int c = 0; c < 256; ++c)
    EXPECT_EQ(ab::err::is_wrong_state(static_cast<uint8_t>(c)), c >= 0xE0 && c <= 0xEF) << c;
}

TEST(KnitEmuFirmware, CnfInfoIs22BytesWithAnEmptySuffix) {
  Rig rig(opts());
  rig.send(ab::ReqInfo{});
  const ab::Bytes framed = rig.fw.take_output();
  const auto packets = ab::SlipDecoder{}.feed(framed);
  ASSERT_EQ(packets.size(), 1u);
  const ab::Bytes expected = {0xC3, 6, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  EXPECT_EQ(packets[0], expected) << "release firmware 1.0.0: API 6, version 1.0.0, no suffix";

  FirmwareOptions o = opts();
  o.suffix = "rc2";
  Rig suffixed(o);
  suffixed.send(ab::ReqInfo{});
  EXPECT_EQ(only<ab::CnfInfo>(suffixed.take()).suffix, "rc2");
}

TEST(KnitEmuFirmware, ReqInitTakesAnyMachineButNone) {
  // initMachine accepts every byte but 0xFF (NoMachine), and only in wait-for-machine.
  for (uint8_t machine : {0, 1, 2, 7, 0xFE}) {
    Rig rig(opts());
    rig.send_payload([&] {
      ab::Bytes b = {0x05, machine};
      b.push_back(ab::crc8(b.data(), b.size()));
      return b;
    }());
    EXPECT_EQ(only<ab::CnfInit>(rig.take()).error, ab::err::success) << int(machine);
    EXPECT_EQ(rig.fw.state(), ab::FsmState::init);
  }
  Rig rig(opts());
  ab::Bytes none = {0x05, 0xFF};
  none.push_back(ab::crc8(none.data(), none.size()));
  rig.send_payload(none);
  EXPECT_EQ(only<ab::CnfInit>(rig.take()).error, ab::err::no_machine_type);
  ab::Bytes bad = ab::encode(ab::ReqInit{ab::MachineType::kh930});
  bad.back() ^= 0x80;
  rig.send_payload(bad);
  EXPECT_EQ(only<ab::CnfInit>(rig.take()).error, ab::err::checksum_error);
  rig.send_payload({0x05, 0x01});
  EXPECT_EQ(only<ab::CnfInit>(rig.take()).error, ab::err::expected_longer_message);
  EXPECT_EQ(rig.fw.state(), ab::FsmState::wait_for_machine);
  rig.send(ab::ReqInit{ab::MachineType::kh930});
  EXPECT_EQ(only<ab::CnfInit>(rig.take()).error, ab::err::success);
  rig.send(ab::ReqInit{ab::MachineType::kh930});
  EXPECT_EQ(only<ab::CnfInit>(rig.take()).error, ab::err::wrong_machine_state) << "init";
  rig.run_until([&] { return rig.fw.state() == ab::FsmState::ready; });
  rig.take();
  rig.send(ab::ReqInit{ab::MachineType::kh930});
  EXPECT_EQ(only<ab::CnfInit>(rig.take()).error, ab::err::wrong_machine_state) << "ready";
}

TEST(KnitEmuFirmware, ReqStartChecksStateAndRange) {
  Rig rig(opts());
  rig.send(ab::ReqStart{0, 10, false, false});
  EXPECT_EQ(only<ab::CnfStart>(rig.take()).error, ab::err::wrong_machine_state) << "before init";
  rig.send(ab::ReqInit{ab::MachineType::kh930});
  rig.take();
  rig.send(ab::ReqStart{0, 10, false, false});
  EXPECT_EQ(only<ab::CnfStart>(rig.take()).error, ab::err::wrong_machine_state) << "init, not ready yet";
  rig.run_until([&] { return rig.fw.state() == ab::FsmState::ready; });
  rig.take();
  for (auto [a, b] : {std::pair{50, 50}, {60, 10}, {0, 200}, {199, 255}}) {
    rig.send(ab::ReqStart{static_cast<uint8_t>(a), static_cast<uint8_t>(b), false, false});
    EXPECT_EQ(only<ab::CnfStart>(rig.take()).error, ab::err::needle_value_invalid) << a << ".." << b;
  }
  ab::Bytes bad = ab::encode(ab::ReqStart{0, 10, false, false});
  bad.back() ^= 1;
  rig.send_payload(bad);
  EXPECT_EQ(only<ab::CnfStart>(rig.take()).error, ab::err::checksum_error);
  rig.send_payload({0x01, 0, 10, 0});
  EXPECT_EQ(only<ab::CnfStart>(rig.take()).error, ab::err::expected_longer_message);
  EXPECT_EQ(rig.fw.state(), ab::FsmState::ready);
  rig.send(ab::ReqStart{0, 199, false, false});
  const auto msgs = rig.take();
  ASSERT_EQ(msgs.size(), 2u) << "the first job after power-on asks for line 0 at once";
  EXPECT_EQ(std::get<ab::CnfStart>(msgs[0]).error, 0);
  EXPECT_EQ(std::get<ab::ReqLine>(msgs[1]).line, 0);
  rig.send(ab::ReqStart{0, 199, false, false});
  EXPECT_EQ(only<ab::CnfStart>(rig.take()).error, ab::err::wrong_machine_state) << "knitting";
}

TEST(KnitEmuFirmware, AReqStartRefusedWhileKnittingStillBlanksTheBuffer) {
  // h_reqStart blanks the line buffer before startKnitting checks the state.
  Rig rig(opts());
  rig.make_ready();
  rig.start(0, 7);
  rig.send(rig.line(0, "11111111"));
  rig.send(ab::ReqStart{0, 7, false, false});
  EXPECT_EQ(all_of<ab::CnfStart>(rig.take()).at(0).error, ab::err::wrong_machine_state);
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  ASSERT_EQ(rig.rows.size(), 1u);
  EXPECT_EQ(rig.rows[0].needles, "00000000") << "the carriage knitted the blanked buffer";
}

TEST(KnitEmuFirmware, UnknownIdsAreIgnoredAndReqInfoAlwaysAnswered) {
  Rig rig(opts());
  rig.send_payload({0x77, 1, 2});
  rig.send_raw({0xC0, 0xC0});  // empty packets
  EXPECT_TRUE(rig.take().empty());
  rig.make_ready();
  rig.start(0, 9);
  rig.send(ab::ReqInfo{});
  EXPECT_EQ(only<ab::CnfInfo>(rig.take()).api, 6) << "reqInfo while knitting";
}

TEST(KnitEmuFirmware, ACnfLineOverwritesTheBufferBeforeItsCrcIsChecked) {
  Rig rig(opts());
  rig.make_ready();
  rig.start(0, 7);
  rig.send(rig.line(0, "10000001"));
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  rig.take();
  ab::Bytes bad = ab::encode(rig.line(1, "11110000"));
  bad.back() ^= 0x5A;
  rig.send_payload(bad);
  EXPECT_TRUE(rig.take().empty()) << "a bad CRC gets no answer";
  // No beep: the knitter waits its patience (2 row-times), then pushes: the garbled copy is
  // knitted and the firmware, still waiting for line 1, asks for nothing.
  EXPECT_TRUE(rig.run_until([&] { return rig.rows.size() == 2; }));
  EXPECT_EQ(rig.rows[1].needles, "11110000");
  EXPECT_TRUE(rig.rows[1].stale);
  EXPECT_TRUE(all_of<ab::ReqLine>(rig.take()).empty()) << "the firmware never asks again";
  // The good copy is still taken: line 1 was requested all along.
  rig.send(rig.line(1, "00001111"));
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  ASSERT_EQ(rig.rows.size(), 3u);
  EXPECT_EQ(rig.rows[2].needles, "00001111");
  EXPECT_FALSE(rig.rows[2].stale);
  EXPECT_EQ(all_of<ab::ReqLine>(rig.take()).at(0).line, 2);
}

TEST(KnitEmuFirmware, AShortCnfLineChangesNothing) {
  Rig rig(opts());
  rig.make_ready();
  rig.start(0, 7);
  rig.send(rig.line(0, "10101010"));
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  rig.take();
  ab::Bytes short_line = ab::encode(rig.line(1, "01010101"));
  short_line.resize(short_line.size() - 1);  // lineBytes + 4: one short
  rig.send_payload(short_line);
  EXPECT_TRUE(rig.run_until([&] { return rig.rows.size() == 2; }));
  EXPECT_EQ(rig.rows[1].needles, "10101010") << "the buffer still held line 0";
  EXPECT_TRUE(rig.rows[1].stale);
}

TEST(KnitEmuFirmware, WrongLineNumberMakesTheFirmwareAskAgain) {
  Rig rig(opts());
  rig.make_ready();
  rig.start(0, 9);
  rig.send(rig.line(5, "1"));
  EXPECT_EQ(only<ab::ReqLine>(rig.take()).line, 0);
  rig.send(rig.line(0, "1"));
  EXPECT_TRUE(rig.take().empty()) << "accepted: no answer but the beep";
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  EXPECT_EQ(rig.rows.at(0).needles, "1000000000");
  // A line nobody asked for (the carriage is knitting it) is copied into the buffer, nothing
  // else: no reqLine, no beep.
  rig.take();
  const int beeps = rig.fw.beeps();
  rig.send(rig.line(1, "01"));
  rig.send(rig.line(1, "11"));
  EXPECT_EQ(rig.fw.beeps(), beeps + 1) << "the first copy of line 1 is accepted, the second is not asked for";
  EXPECT_TRUE(rig.take().empty());
}

TEST(KnitEmuFirmware, LineNumbersWrapAt256) {
  Rig rig(opts(ab::MachineType::kh930, 5));
  rig.make_ready();
  rig.start(0, 7);
  for (int i = 0; i < 300; ++i) {
    rig.take();
    rig.send(rig.line(static_cast<uint8_t>(i & 0xFF), i % 2 ? "01" : "10"));
    ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
    ASSERT_EQ(all_of<ab::ReqLine>(rig.take()).at(0).line, static_cast<uint8_t>((i + 1) & 0xFF)) << "after line " << i;
  }
  ASSERT_EQ(rig.rows.size(), 300u);
  EXPECT_EQ(rig.rows[299].number, 300);
  EXPECT_EQ(rig.rows[256].line, 0);
  EXPECT_EQ(rig.rows[299].needles, "01000000");
}

TEST(KnitEmuFirmware, NeedleBitOrderIsLsbFirstFromNeedleZero) {
  Rig rig(opts());
  rig.make_ready();
  rig.start(0, 15);
  ab::CnfLine c;
  c.line = 0;
  c.needles.assign(25, 0);
  c.needles[0] = 0x01;  // bit 0 of byte 0: needle 0, the leftmost
  c.needles[1] = 0x80;  // bit 7 of byte 1: needle 15
  rig.send(c);
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  ASSERT_EQ(rig.rows.size(), 1u);
  EXPECT_EQ(rig.rows[0].needles, "1000000000000001");

  // A range further right: needle 20 is bit 4 of byte 2 and is the first recorded character;
  // selections outside the working range are not recorded.
  Rig right(opts());
  right.make_ready();
  right.start(20, 27);
  c.needles.assign(25, 0);
  c.needles[0] = 0xFF;
  c.needles[2] = 0x10;
  c.needles[3] = 0x08;  // needle 27
  right.send(c);
  ASSERT_TRUE(right.run_until_sent<ab::ReqLine>());
  ASSERT_EQ(right.rows.size(), 1u);
  EXPECT_EQ(right.rows[0].needles, "10000001");
  EXPECT_EQ(right.rows[0].start_needle, 20);
  EXPECT_EQ(right.rows[0].stop_needle, 27);
}

TEST(KnitEmuFirmware, Kh270Has112NeedlesAnd14ByteLines) {
  Rig rig(opts(ab::MachineType::kh270));
  rig.make_ready();
  rig.send(ab::ReqStart{0, 112, false, false});
  EXPECT_EQ(only<ab::CnfStart>(rig.take()).error, ab::err::needle_value_invalid);
  rig.start(0, 111);
  std::string pattern(112, '0');
  pattern[0] = pattern[111] = pattern[57] = '1';
  const ab::CnfLine c = rig.line(0, pattern);
  ASSERT_EQ(c.needles.size(), 14u);
  ASSERT_EQ(ab::encode(c).size(), 19u);
  rig.send(c);
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  EXPECT_EQ(all_of<ab::ReqLine>(rig.take()).at(0).line, 1);
  ASSERT_EQ(rig.rows.size(), 1u);
  EXPECT_EQ(rig.rows[0].needles, pattern);
}

TEST(KnitEmuFirmware, BootLosesInputForBootMsAfterPowerOn) {
  FirmwareOptions o = opts();
  o.boot_ms = 200;
  Rig rig(o);
  rig.send(ab::ReqInfo{});
  rig.advance(199);
  rig.send(ab::ReqInfo{});
  EXPECT_TRUE(rig.take().empty());
  rig.advance(1);
  rig.send(ab::ReqInfo{});
  EXPECT_EQ(only<ab::CnfInfo>(rig.take()).api, 6);
}

TEST(KnitEmuFirmware, AnEscapeFollowedByAnInvalidByteHangsTheBoardUntilReset) {
  Rig rig(opts());
  rig.make_ready();
  rig.send_raw({0xC0, 0x03, 0xDB, 0x41, 0xC0});  // reqInfo with ESC 'A' in it
  EXPECT_TRUE(rig.fw.hung());
  rig.send(ab::ReqInfo{});
  rig.send(ab::ReqStart{0, 9, false, false});
  EXPECT_TRUE(rig.take().empty()) << "a hung board answers nothing";
  EXPECT_EQ(rig.fw.next_event_ms(), std::nullopt) << "and nothing moves";
  // A packet ending in ESC hangs too; the host's own decoder only drops such a packet.
  Rig other(opts());
  other.send_raw({0xC0, 0x03, 0xDB, 0xC0});
  EXPECT_TRUE(other.fw.hung());
  EXPECT_TRUE(ab::SlipDecoder{}.feed(ab::Bytes{0xC0, 0x03, 0xDB, 0x41, 0xC0, 0x03, 0xC0}).size() == 1);
  // The reset (a new firmware) answers again; valid escapes are decoded.
  Rig reset(opts());
  ab::Bytes info = {0xC0, 0x03, 0xC0};
  reset.send_raw(info);
  EXPECT_EQ(only<ab::CnfInfo>(reset.take()).api, 6);
  ab::Bytes start = ab::encode(ab::ReqInit{ab::MachineType::kh930});
  reset.send_raw(ab::slip_encode(start));
  EXPECT_EQ(only<ab::CnfInit>(reset.take()).error, 0);
}

TEST(KnitEmuFaults, Api5IsReportedInCnfInfo) {
  FirmwareOptions o;
  o.faults.api = 5;
  Rig rig(o);
  rig.send(ab::ReqInfo{});
  EXPECT_EQ(only<ab::CnfInfo>(rig.take()).api, 5);
}

TEST(KnitEmuFaults, DelayHoldsEveryReply) {
  FirmwareOptions o;
  o.faults.delay_ms = 50;
  Rig rig(o);
  rig.send(ab::ReqInfo{});
  rig.advance(49);
  EXPECT_TRUE(rig.take().empty());
  EXPECT_EQ(rig.fw.next_event_ms(), 50);
  rig.advance(1);
  EXPECT_EQ(rig.take().size(), 1u);
}

TEST(KnitEmuFaults, SilentAfterRowAnswersNothing) {
  FirmwareOptions o = opts(ab::MachineType::kh930, 10);
  o.faults.silent_after_row = 2;
  Rig rig(o);
  rig.make_ready();
  rig.start(0, 9);
  rig.send(rig.line(0, "1"));
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  EXPECT_EQ(all_of<ab::ReqLine>(rig.take()).at(0).line, 1);
  rig.send(rig.line(1, "1"));
  rig.run_until([] { return false; });
  EXPECT_EQ(rig.rows.size(), 2u);
  EXPECT_TRUE(rig.take().empty()) << "no reqLine after row 2";
  rig.send(ab::ReqInfo{});
  rig.send(rig.line(2, "1"));
  rig.advance(1000);
  EXPECT_TRUE(rig.take().empty());
  EXPECT_TRUE(rig.fw.silent());
}

TEST(KnitEmuFaults, CorruptLineGarblesTheNthCnfLineCountedOverTheEmulatorsLife) {
  FirmwareOptions o = opts();
  o.faults.corrupt_line = 3;
  o.cnf_lines_before = 1;  // one cnfLine went to an earlier life of the board
  Rig rig(o);
  rig.make_ready();
  rig.start(8, 15);
  rig.send(rig.line(0, "0000000011110000"));
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  rig.take();
  rig.send(rig.line(1, "0000000000001111"));  // the 3rd over the life: byte of needle 8 flipped
  EXPECT_EQ(rig.fw.cnf_lines_received(), 3);
  EXPECT_TRUE(rig.run_until([&] { return rig.rows.size() == 2; }));
  EXPECT_EQ(rig.rows[1].needles, "11110000") << "needles 8..15 inverted, knitted as they stood";
  EXPECT_TRUE(rig.rows[1].stale);
  EXPECT_TRUE(rig.take().empty()) << "nothing after the garbled line";
  rig.send(rig.line(1, "0000000000001111"));
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  EXPECT_EQ(rig.rows.at(2).needles, "00001111") << "the good copy is knitted next";
}

TEST(KnitEmuFaults, BadEscapeAfterRowHangsOnTheNextMessage) {
  FirmwareOptions o = opts();
  o.faults.bad_escape_after_row = 1;
  Rig rig(o);
  rig.make_ready();
  rig.start(0, 7);
  rig.send(rig.line(0, "1"));
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>()) << "row 1's reqLine still goes out";
  EXPECT_FALSE(rig.fw.hung());
  rig.take();
  rig.send(rig.line(1, "01"));
  EXPECT_TRUE(rig.fw.hung());
  rig.send(ab::ReqInfo{});
  EXPECT_FALSE(rig.run_until([&] { return !rig.take().empty() || rig.rows.size() > 1; }));
  EXPECT_EQ(rig.rows.size(), 1u);
}

// A host that re-sends each message until the firmware answers (within 50 ms), with a patient
// knitter (1 s), so that a good copy always replaces a corrupted one before the carriage moves.
struct Outcome {
  std::vector<std::string> record;
  int resends = 0;
  std::vector<std::string> stream;  // everything the firmware sent, described
};

Outcome knit_through_noise(uint64_t seed, const std::vector<std::string>& lines) {
  FirmwareOptions o;
  o.row_ms = 10;
  o.faults.corrupt = 0.02;
  o.faults.seed = seed;
  o.faults.knitter_patience_ms = 1000;
  Rig rig(o);
  Outcome out;
  auto exchange = [&](const ab::Message& m, auto done) {
    for (int attempt = 0; attempt < 50; ++attempt) {
      if (attempt > 0) ++out.resends;
      rig.send(m);
      for (int wait = 0; wait < 5; ++wait) {
        rig.advance(10);
        for (const auto& msg : rig.take()) {
          out.stream.push_back(ab::describe(msg));
          if (done(msg)) return true;
        }
      }
    }
    return false;
  };
  EXPECT_TRUE(exchange(ab::ReqInit{ab::MachineType::kh930}, [](const ab::Message& m) {
    auto* c = std::get_if<ab::CnfInit>(&m);
    return c && c->error == 0;
  }));
  rig.run_until([&] { return rig.fw.state() == ab::FsmState::ready; });
  rig.take();
  EXPECT_TRUE(exchange(ab::ReqStart{0, 15, false, false}, [](const ab::Message& m) {
    auto* r = std::get_if<ab::ReqLine>(&m);
    return r && r->line == 0;
  }));
  for (size_t i = 0; i < lines.size(); ++i) {
    const uint8_t next = static_cast<uint8_t>(i + 1);
    EXPECT_TRUE(exchange(rig.line(static_cast<uint8_t>(i), lines[i]), [&](const ab::Message& m) {
      auto* r = std::get_if<ab::ReqLine>(&m);
      return r && r->line == next;
    })) << "line " << i << " never confirmed";
  }
  EXPECT_FALSE(rig.fw.hung()) << "seed " << seed << " made an invalid SLIP escape: pick another";
  for (const auto& r : rig.rows) out.record.push_back(r.needles);
  return out;
}

TEST(KnitEmuFaults, CorruptionIsReproducibleBySeedAndBadLinesAreResent) {
  std::vector<std::string> lines;
  for (int i = 0; i < 40; ++i) {
    std::string l(16, '0');
    for (int n = 0; n < 16; ++n) l[static_cast<size_t>(n)] = ((n * 7 + i * 3) % 5 < 2) ? '1' : '0';
    lines.push_back(l);
  }
  const Outcome a = knit_through_noise(7, lines);
  const Outcome b = knit_through_noise(7, lines);
  EXPECT_GT(a.resends, 0) << "2% corruption over 40 lines should hit some message";
  EXPECT_EQ(a.resends, b.resends);
  EXPECT_EQ(a.stream, b.stream);
  EXPECT_EQ(a.record, lines) << "a corrupted line was knitted";
  EXPECT_EQ(b.record, lines);
}

}  // namespace
}  // namespace atelier::knit_emu::testing
