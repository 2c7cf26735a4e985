// The pure AYAB v6 firmware model (tools/knit_emu/firmware.h) driven by encoded messages on a
// simulated clock, and the faults it implements (corrupt, silent, api, delay).
#include <gtest/gtest.h>

#include "tests/support/knit_emu_rig.h"

namespace atelier::knit_emu::testing {
namespace {

template <class T>
T only(const std::vector<ab::Message>& msgs) {
  EXPECT_EQ(msgs.size(), 1u);
  const T* m = msgs.empty() ? nullptr : std::get_if<T>(&msgs.front());
  if (!m) {
    ADD_FAILURE() << "expected one message of the right type, got "
                  << (msgs.empty() ? std::string("nothing") : ab::describe(msgs.front()));
    return T{};
  }
  return *m;
}

FirmwareOptions opts(ab::MachineType m = ab::MachineType::kh930, int64_t row_ms = 100) {
  FirmwareOptions o;
  o.machine = m;
  o.row_ms = row_ms;
  return o;
}

TEST(KnitEmuFirmware, FullSessionRecordsTheLinesSent) {
  Rig rig(opts());
  rig.send(ab::ReqInfo{});
  const auto& info = only<ab::CnfInfo>(rig.take());
  EXPECT_EQ(info.api, 6);
  EXPECT_EQ(info.fw_major, 1);
  EXPECT_EQ(info.fw_minor, 0);
  EXPECT_EQ(info.fw_patch, 0);
  EXPECT_EQ(info.suffix, "atelier-emu");

  rig.send(ab::ReqInit{ab::MachineType::kh930});
  EXPECT_EQ(only<ab::CnfInit>(rig.take()).error, ab::err::success);
  EXPECT_EQ(rig.fw.state(), ab::FsmState::init);
  rig.advance(99);
  EXPECT_TRUE(rig.take().empty()) << "ready before the carriage reached the turn mark";
  rig.advance(1);
  const auto& ready = only<ab::IndState>(rig.take());
  EXPECT_EQ(ready.error, 0);
  EXPECT_EQ(ready.state, ab::FsmState::ready);
  EXPECT_EQ(ready.carriage, ab::Carriage::knit);
  EXPECT_EQ(ready.direction, ab::Direction::right);

  rig.send(ab::ReqStart{10, 17, false, true});
  auto msgs = rig.take();
  ASSERT_EQ(msgs.size(), 2u);
  EXPECT_EQ(std::get<ab::CnfStart>(msgs[0]).error, 0);
  EXPECT_EQ(std::get<ab::ReqLine>(msgs[1]).line, 0);

  // Needles 10..17; the host puts them at their absolute bit positions.
  const std::vector<std::string> rows = {"10110001", "01000010", "11111111"};
  for (uint8_t n = 0; n < rows.size(); ++n) {
    rig.send(rig.line(n, std::string(10, '0') + rows[n]));
    rig.advance(100);
    EXPECT_EQ(only<ab::ReqLine>(rig.take()).line, n + 1);
  }
  rig.send(rig.line(3, "", true));
  rig.advance(100);
  EXPECT_TRUE(rig.take().empty()) << "nothing is sent after the last line";
  EXPECT_EQ(rig.fw.state(), ab::FsmState::init);
  ASSERT_EQ(rig.rows.size(), 3u) << "the blank last line is not recorded";
  for (size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rig.rows[i].needles, rows[i]);
    EXPECT_EQ(rig.rows[i].number, static_cast<int>(i + 1));
  }

  // Back to ready as the carriage passes the turn mark: a second job needs no reqInit.
  rig.advance(100);
  EXPECT_EQ(only<ab::IndState>(rig.take()).state, ab::FsmState::ready);
  rig.send(ab::ReqInit{ab::MachineType::kh930});
  EXPECT_EQ(only<ab::CnfInit>(rig.take()).error, ab::err::wrong_machine_state);
  rig.send(ab::ReqStart{0, 199, false, false});
  msgs = rig.take();
  ASSERT_EQ(msgs.size(), 2u);
  EXPECT_EQ(std::get<ab::CnfStart>(msgs[0]).error, 0);
  EXPECT_EQ(std::get<ab::ReqLine>(msgs[1]).line, 0);
}

TEST(KnitEmuFirmware, NeedleBitOrderIsLsbFirstFromNeedleZero) {
  Rig rig(opts());
  rig.make_ready();
  rig.send(ab::ReqStart{0, 15, false, false});
  rig.take();
  ab::CnfLine c;
  c.line = 0;
  c.needles.assign(25, 0);
  c.needles[0] = 0x01;  // bit 0 of byte 0: needle 0, the leftmost
  c.needles[1] = 0x80;  // bit 7 of byte 1: needle 15
  rig.send(c);
  rig.advance(100);
  ASSERT_EQ(rig.rows.size(), 1u);
  EXPECT_EQ(rig.rows[0].needles, "1000000000000001");

  // A range further right: needle 20 is bit 4 of byte 2 and is the first recorded character;
  // selections outside the working range are not recorded.
  Rig right(opts());
  right.make_ready();
  right.send(ab::ReqStart{20, 27, false, false});
  right.take();
  c.needles.assign(25, 0);
  c.needles[0] = 0xFF;
  c.needles[2] = 0x10;
  c.needles[3] = 0x08;  // needle 27
  right.send(c);
  right.advance(100);
  ASSERT_EQ(right.rows.size(), 1u);
  EXPECT_EQ(right.rows[0].needles, "10000001");
  EXPECT_EQ(right.rows[0].start_needle, 20);
  EXPECT_EQ(right.rows[0].stop_needle, 27);
}

TEST(KnitEmuFirmware, NextLineIsRequestedOnlyAfterTheCarriagePass) {
  Rig rig(opts(ab::MachineType::kh930, 2000));
  rig.make_ready();
  rig.send(ab::ReqStart{0, 199, false, false});
  rig.take();
  rig.send(rig.line(0, "1"));
  rig.advance(1999);
  EXPECT_TRUE(rig.take().empty());
  EXPECT_TRUE(rig.rows.empty()) << "row recorded before the carriage finished the pass";
  // A cnfLine before the request is ignored (the carriage is still knitting).
  rig.send(rig.line(1, "1"));
  EXPECT_TRUE(rig.take().empty());
  rig.advance(1);
  EXPECT_EQ(rig.rows.size(), 1u);
  EXPECT_EQ(only<ab::ReqLine>(rig.take()).line, 1);
  EXPECT_EQ(rig.fw.next_event_ms(), std::nullopt) << "idle while waiting for the host";
}

TEST(KnitEmuFirmware, LineNumbersWrapAt256) {
  Rig rig(opts(ab::MachineType::kh930, 5));
  rig.make_ready();
  rig.send(ab::ReqStart{0, 7, false, false});
  EXPECT_EQ(rig.take().size(), 2u);
  for (int i = 0; i < 300; ++i) {
    rig.send(rig.line(static_cast<uint8_t>(i & 0xFF), i % 2 ? "01" : "10"));
    rig.advance(5);
    ASSERT_EQ(only<ab::ReqLine>(rig.take()).line, static_cast<uint8_t>((i + 1) & 0xFF)) << "after line " << i;
  }
  ASSERT_EQ(rig.rows.size(), 300u);
  EXPECT_EQ(rig.rows[299].number, 300);
  EXPECT_EQ(rig.rows[256].line, 0);
  EXPECT_EQ(rig.rows[299].needles, "01000000");
}

TEST(KnitEmuFirmware, BadCrcCnfLineIsSilentlyDroppedThenTheGoodCopyAccepted) {
  Rig rig(opts());
  rig.make_ready();
  rig.send(ab::ReqStart{0, 9, false, false});
  rig.take();
  ab::Bytes bad = ab::encode(rig.line(0, "1111"));
  bad.back() ^= 0x5A;
  rig.send_payload(bad);
  ab::Bytes short_line = ab::encode(rig.line(0, "1111"));
  short_line.resize(10);
  rig.send_payload(short_line);
  rig.advance(500);
  EXPECT_TRUE(rig.take().empty()) << "a bad cnfLine got an answer";
  EXPECT_TRUE(rig.rows.empty());
  rig.send(rig.line(0, "1111"));
  rig.advance(100);
  EXPECT_EQ(only<ab::ReqLine>(rig.take()).line, 1);
  ASSERT_EQ(rig.rows.size(), 1u);
  EXPECT_EQ(rig.rows[0].needles, "1111000000");
}

TEST(KnitEmuFirmware, WrongLineNumberMakesTheFirmwareAskAgain) {
  Rig rig(opts());
  rig.make_ready();
  rig.send(ab::ReqStart{0, 9, false, false});
  rig.take();
  rig.send(rig.line(5, "1"));
  EXPECT_EQ(only<ab::ReqLine>(rig.take()).line, 0);
  rig.advance(500);
  EXPECT_TRUE(rig.rows.empty());
}

TEST(KnitEmuFirmware, ReqStartChecksStateAndRange) {
  Rig rig(opts());
  rig.send(ab::ReqStart{0, 10, false, false});
  EXPECT_EQ(only<ab::CnfStart>(rig.take()).error, ab::err::wrong_machine_state) << "before init";
  rig.send(ab::ReqInit{ab::MachineType::kh930});
  rig.take();
  rig.send(ab::ReqStart{0, 10, false, false});
  EXPECT_EQ(only<ab::CnfStart>(rig.take()).error, ab::err::wrong_machine_state) << "init, not ready yet";
  rig.advance(100);
  rig.take();
  for (auto [a, b] : {std::pair{50, 50}, {60, 10}, {0, 200}, {199, 255}}) {
    rig.send(ab::ReqStart{static_cast<uint8_t>(a), static_cast<uint8_t>(b), false, false});
    EXPECT_EQ(only<ab::CnfStart>(rig.take()).error, ab::err::bad_needles) << a << ".." << b;
  }
  ab::Bytes bad = ab::encode(ab::ReqStart{0, 10, false, false});
  bad.back() ^= 1;
  rig.send_payload(bad);
  EXPECT_EQ(only<ab::CnfStart>(rig.take()).error, ab::err::bad_crc);
  EXPECT_EQ(rig.fw.state(), ab::FsmState::ready);
}

TEST(KnitEmuFirmware, ReqInitOnlyInWaitForMachineAndForThisMachine) {
  Rig rig(opts());
  rig.send(ab::ReqInit{ab::MachineType::kh270});
  EXPECT_EQ(only<ab::CnfInit>(rig.take()).error, ab::err::bad_argument);
  ab::Bytes bad = ab::encode(ab::ReqInit{ab::MachineType::kh930});
  bad.back() ^= 0x80;
  rig.send_payload(bad);
  EXPECT_EQ(only<ab::CnfInit>(rig.take()).error, ab::err::bad_crc);
  rig.send_payload({0x05});
  EXPECT_EQ(only<ab::CnfInit>(rig.take()).error, ab::err::too_short);
  EXPECT_EQ(rig.fw.state(), ab::FsmState::wait_for_machine);
  rig.send(ab::ReqInit{ab::MachineType::kh930});
  EXPECT_EQ(only<ab::CnfInit>(rig.take()).error, ab::err::success);
  rig.send(ab::ReqInit{ab::MachineType::kh930});
  EXPECT_EQ(only<ab::CnfInit>(rig.take()).error, ab::err::wrong_machine_state);
}

TEST(KnitEmuFirmware, UnknownIdsAreIgnoredAndReqInfoAlwaysAnswered) {
  Rig rig(opts());
  rig.send_payload({0x77, 1, 2});
  EXPECT_TRUE(rig.take().empty());
  rig.make_ready();
  rig.send(ab::ReqStart{0, 9, false, false});
  rig.take();
  rig.send(ab::ReqInfo{});
  EXPECT_EQ(only<ab::CnfInfo>(rig.take()).api, 6) << "reqInfo while knitting";
}

TEST(KnitEmuFirmware, Kh270Has112NeedlesAnd14ByteLines) {
  Rig rig(opts(ab::MachineType::kh270));
  rig.send(ab::ReqInit{ab::MachineType::kh930});
  EXPECT_EQ(only<ab::CnfInit>(rig.take()).error, ab::err::bad_argument);
  rig.make_ready();
  rig.send(ab::ReqStart{0, 112, false, false});
  EXPECT_EQ(only<ab::CnfStart>(rig.take()).error, ab::err::bad_needles);
  rig.send(ab::ReqStart{0, 111, false, false});
  EXPECT_EQ(rig.take().size(), 2u);
  std::string pattern(112, '0');
  pattern[0] = pattern[111] = pattern[57] = '1';
  const ab::CnfLine c = rig.line(0, pattern);
  ASSERT_EQ(c.needles.size(), 14u);
  ASSERT_EQ(ab::encode(c).size(), 19u);
  rig.send(c);
  rig.advance(100);
  EXPECT_EQ(only<ab::ReqLine>(rig.take()).line, 1);
  ASSERT_EQ(rig.rows.size(), 1u);
  EXPECT_EQ(rig.rows[0].needles, pattern);
}

TEST(KnitEmuFirmware, ContinuousReportingSendsIndStateAtEachTurn) {
  Rig rig(opts());
  rig.make_ready();
  rig.send(ab::ReqStart{20, 40, true, false});
  rig.take();
  rig.send(rig.line(0, ""));
  rig.advance(100);
  auto msgs = rig.take();
  ASSERT_EQ(msgs.size(), 2u);
  const auto& s = std::get<ab::IndState>(msgs[0]);
  EXPECT_EQ(s.state, ab::FsmState::knit);
  EXPECT_EQ(s.position, 40 + 12) << "carriage stops 12 needles past the working range";
  EXPECT_EQ(std::get<ab::ReqLine>(msgs[1]).line, 1);
  rig.send(rig.line(1, ""));
  rig.advance(100);
  msgs = rig.take();
  ASSERT_EQ(msgs.size(), 2u);
  EXPECT_EQ(std::get<ab::IndState>(msgs[0]).position, 20 - 12);
  EXPECT_EQ(std::get<ab::IndState>(msgs[0]).direction, ab::Direction::left);
}

TEST(KnitEmuFirmware, BootDelayLosesInputAfterTheFirstByte) {
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

TEST(KnitEmuFaults, Api5IsReportedInCnfInfo) {
  FirmwareOptions o;
  o.faults.api = 5;
  Rig rig(o);
  rig.send(ab::ReqInfo{});
  auto msgs = rig.take();
  ASSERT_EQ(msgs.size(), 1u);
  EXPECT_EQ(std::get<ab::CnfInfo>(msgs[0]).api, 5);
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
  FirmwareOptions o;
  o.row_ms = 10;
  o.faults.silent_after_row = 2;
  Rig rig(o);
  rig.make_ready();
  rig.send(ab::ReqStart{0, 9, false, false});
  rig.take();
  for (uint8_t n = 0; n < 2; ++n) {
    rig.send(rig.line(n, "1"));
    rig.advance(10);
  }
  EXPECT_EQ(rig.rows.size(), 2u);
  auto msgs = rig.take();
  ASSERT_EQ(msgs.size(), 1u) << "only the reqLine confirming row 1";
  EXPECT_EQ(std::get<ab::ReqLine>(msgs[0]).line, 1);
  rig.send(ab::ReqInfo{});
  rig.send(rig.line(2, "1"));
  rig.advance(1000);
  EXPECT_TRUE(rig.take().empty());
  EXPECT_TRUE(rig.fw.silent());
}

// A host that re-sends each message until the firmware answers, as the driver does.
struct Outcome {
  std::vector<std::string> record;
  int resends = 0;
  ab::Bytes stream;  // everything the firmware sent
};

Outcome knit_through_noise(uint64_t seed, const std::vector<std::string>& lines) {
  FirmwareOptions o;
  o.row_ms = 10;
  o.faults.corrupt = 0.02;
  o.faults.seed = seed;
  Rig rig(o);
  Outcome out;
  auto exchange = [&](const ab::Message& m, auto done) {
    for (int attempt = 0; attempt < 50; ++attempt) {
      if (attempt > 0) ++out.resends;
      rig.send(m);
      rig.advance(10);
      const ab::Bytes raw = rig.fw.take_output();
      out.stream.insert(out.stream.end(), raw.begin(), raw.end());
      for (const auto& p : rig.dec.feed(raw)) {
        auto d = ab::decode(p, 25);
        if (d.message && done(*d.message)) return true;
      }
    }
    return false;
  };
  auto is_ok = [](const ab::Message& m) {
    if (auto* c = std::get_if<ab::CnfInit>(&m)) return c->error == 0;
    if (auto* s = std::get_if<ab::IndState>(&m)) return s->state == ab::FsmState::ready;
    return false;
  };
  EXPECT_TRUE(exchange(ab::ReqInit{ab::MachineType::kh930}, is_ok));
  rig.advance(10);
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
