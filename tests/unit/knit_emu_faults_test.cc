// Fault injection of the knitting-machine emulator: spec parsing and the faults the pure
// firmware model implements (corrupt, silent, api, delay).
#include <gtest/gtest.h>

#include "tests/unit/knit_emu_rig.h"
#include "tools/knit_emu/faults.h"

namespace atelier::knit_emu::testing {
namespace {

TEST(KnitEmuFaults, ParsesEverySpec) {
  Faults f;
  EXPECT_EQ(apply_fault("drop-after-row=3", f), "");
  EXPECT_EQ(f.drop_after_row, 3);
  EXPECT_EQ(f.replug_ms, 1000);
  EXPECT_EQ(apply_fault("drop-after-row=5:250", f), "");
  EXPECT_EQ(f.drop_after_row, 5);
  EXPECT_EQ(f.replug_ms, 250);
  EXPECT_EQ(apply_fault("replug-ms=40", f), "");
  EXPECT_EQ(f.replug_ms, 40);
  EXPECT_EQ(apply_fault("corrupt=0.25", f), "");
  EXPECT_DOUBLE_EQ(f.corrupt, 0.25);
  EXPECT_EQ(apply_fault("seed=99", f), "");
  EXPECT_EQ(f.seed, 99u);
  EXPECT_EQ(apply_fault("silent-after-row=7", f), "");
  EXPECT_EQ(f.silent_after_row, 7);
  EXPECT_EQ(apply_fault("api=5", f), "");
  EXPECT_EQ(f.api, 5);
  EXPECT_EQ(apply_fault("delay-ms=30", f), "");
  EXPECT_EQ(f.delay_ms, 30);
}

TEST(KnitEmuFaults, RejectsBadSpecsWithAReason) {
  Faults f;
  EXPECT_NE(apply_fault("corrupt=1.5", f).find("corrupt=1.5"), std::string::npos);
  EXPECT_NE(apply_fault("corrupt=x", f), "");
  EXPECT_NE(apply_fault("drop-after-row=0", f), "");
  EXPECT_NE(apply_fault("drop-after-row=2:", f), "");
  EXPECT_NE(apply_fault("delay-ms=-1", f), "");
  EXPECT_NE(apply_fault("api=300", f), "");
  EXPECT_NE(apply_fault("explode=1", f).find("unknown fault"), std::string::npos);
  EXPECT_NE(apply_fault("api", f), "");
  EXPECT_EQ(f.corrupt, 0.0) << "a rejected spec changed the faults";
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
