// The firmware model's carriage, knitter and record (tools/knit_emu/firmware.h): positions in
// the firmware's units, indState at every step, reqLine 13 needles past the working range, the
// old buffer knitted when no line came, the job's end and a second job, as AYAB firmware 1.0.0's
// knitter.cpp / encoders.cpp / encoders.h do.
#include <gtest/gtest.h>

#include "tests/support/knit_emu_rig.h"

namespace atelier::knit_emu::testing {
namespace {

// The indStates sent before the first reqLine in `msgs`.
std::vector<ab::IndState> states_before_req_line(const std::vector<ab::Message>& msgs) {
  std::vector<ab::IndState> out;
  for (const auto& m : msgs) {
    if (std::holds_alternative<ab::ReqLine>(m)) break;
    if (const auto* s = std::get_if<ab::IndState>(&m)) out.push_back(*s);
  }
  return out;
}

TEST(KnitEmuKnitting, TheReadyIndStateComesPastTheLeftTurnMarkAndStillSaysInit) {
  Rig rig(opts());
  rig.send(ab::ReqInit{ab::MachineType::kh930});
  EXPECT_EQ(only<ab::CnfInit>(rig.take()).error, 0);
  ASSERT_TRUE(rig.run_until_sent<ab::IndState>());
  const auto s = only<ab::IndState>(rig.take());
  EXPECT_EQ(s.error, 0);
  EXPECT_EQ(s.state, ab::FsmState::init) << "the FSM moves to ready after the dispatch that sent it";
  EXPECT_EQ(s.carriage, ab::Carriage::knit);
  EXPECT_EQ(s.position, 31) << "isReady: moving right, past END_LEFT_PLUS_OFFSET (28) + GARTER_SLOP (2)";
  EXPECT_EQ(s.direction, ab::Direction::right);
  EXPECT_EQ(s.hall_left, 440) << "past the sensor: idle";
  EXPECT_EQ(s.hall_right, 358);
  EXPECT_EQ(rig.fw.state(), ab::FsmState::ready);
}

TEST(KnitEmuKnitting, AfterAResetTheKnitterTakesTheCarriageBackOverTheLeftTurnMark) {
  FirmwareOptions o = opts();
  o.carriage_position = 240;  // where the last firmware life left it: right of the right sensor
  Rig rig(o);
  rig.send(ab::ReqInit{ab::MachineType::kh930});
  rig.take();
  ASSERT_TRUE(rig.run_until([&] { return rig.fw.state() == ab::FsmState::ready; }));
  const auto s = only<ab::IndState>(rig.take());
  // Moving left over the right sensor also makes the machine ready (isReady's passedRight).
  EXPECT_EQ(s.position, 224);
  EXPECT_EQ(s.direction, ab::Direction::left);
  rig.run_until([] { return false; });
  EXPECT_EQ(rig.fw.carriage_position(), Firmware::kReadyPosition);
}

TEST(KnitEmuKnitting, NothingIsSeenOfTheCarriageBeforeReqInit) {
  Rig rig(opts());
  rig.fw.push_carriage(100, 50);
  rig.run_until([] { return false; });
  EXPECT_EQ(rig.fw.carriage_position(), 100);
  EXPECT_TRUE(rig.take().empty());
  EXPECT_EQ(rig.fw.state(), ab::FsmState::wait_for_machine);
}

TEST(KnitEmuKnitting, WithContinuousReportingEveryStepSendsAnIndStateAndReqLineComes13NeedlesPast) {
  Rig rig(opts());
  rig.make_ready();
  rig.start(50, 80, true);
  rig.send(rig.line(0, ""));
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  auto msgs = rig.take();
  auto states = states_before_req_line(msgs);
  ASSERT_GT(states.size(), 50u);
  for (size_t i = 0; i < states.size(); ++i) {
    EXPECT_EQ(states[i].state, ab::FsmState::knit);
    EXPECT_EQ(states[i].error, 0);
    EXPECT_EQ(states[i].direction, ab::Direction::right);
    EXPECT_EQ(states[i].carriage, ab::Carriage::knit);
    if (i > 0) {
      EXPECT_EQ(states[i].position, states[i - 1].position + 1) << "a step was not reported";
    }
  }
  // Moving right the pixel is position - 42: the line ends at pixel stop + 13.
  EXPECT_EQ(states.back().position, 80 + 13 + 42);
  EXPECT_EQ(all_of<ab::ReqLine>(msgs).at(0).line, 1);

  rig.send(rig.line(1, ""));
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  states = states_before_req_line(rig.take());
  ASSERT_FALSE(states.empty());
  EXPECT_EQ(states.front().position, 80 + 13 + 42 + 2 - 1) << "the pass starts where the knitter turned";
  EXPECT_EQ(states.back().direction, ab::Direction::left);
  // Moving left the pixel is position - 16: the line ends at pixel start - 13.
  EXPECT_EQ(states.back().position, 50 - 13 + 16);
}

TEST(KnitEmuKnitting, TheHallSensorsReadTheKCarriageAsItPassesThem) {
  Rig rig(opts());
  rig.make_ready();
  rig.start(0, 199, true);
  rig.send(rig.line(0, ""));
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  std::vector<ab::IndState> right = all_of<ab::IndState>(rig.take());
  rig.send(rig.line(1, ""));
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  std::vector<ab::IndState> left = all_of<ab::IndState>(rig.take());
  int right_high = 0, left_high = 0;
  for (const auto& s : right) {
    const bool over = s.position >= 225 && s.position <= 227;
    EXPECT_EQ(s.hall_right, over ? 747 : 358) << "position " << int(s.position);
    right_high += over;
  }
  for (const auto& s : left) {
    const bool over = s.position >= 28 && s.position <= 30;
    EXPECT_EQ(s.hall_left, over ? 757 : 440) << "position " << int(s.position);
    left_high += over;
  }
  EXPECT_EQ(right_high, 3) << "the pass to the right went over the right sensor";
  EXPECT_EQ(left_high, 3) << "the pass to the left went over the left sensor";
}

TEST(KnitEmuKnitting, Kh270FinishesALine7NeedlesPast) {
  Rig rig(opts(ab::MachineType::kh270));
  rig.make_ready();
  rig.start(10, 40, true);
  rig.send(rig.line(0, ""));
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  EXPECT_EQ(states_before_req_line(rig.take()).back().position, 40 + 7 + 34);
  rig.send(rig.line(1, ""));
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  EXPECT_EQ(states_before_req_line(rig.take()).back().position, 10 - 7 + 22);
}

TEST(KnitEmuKnitting, AJobEndsOnePassAfterTheLastLineAndASecondJobKnitsABlankPassFirst) {
  Rig rig(opts());
  rig.make_ready();
  rig.send(ab::ReqStart{10, 17, false, true});
  auto msgs = rig.take();
  ASSERT_EQ(msgs.size(), 2u);
  EXPECT_EQ(std::get<ab::ReqLine>(msgs[1]).line, 0) << "first job after power-on: reqLine(0) at once";
  const std::vector<std::string> rows = {"10110001", "01000010", "11111111"};
  for (uint8_t n = 0; n < rows.size(); ++n) {
    rig.send(rig.line(n, std::string(10, '0') + rows[n]));
    ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
    EXPECT_EQ(all_of<ab::ReqLine>(rig.take()).at(0).line, n + 1);
  }
  rig.send(rig.line(3, "", true));
  ASSERT_TRUE(rig.run_until([&] { return rig.fw.state() != ab::FsmState::knit; }));
  EXPECT_EQ(rig.fw.state(), ab::FsmState::init) << "the blank pass ended the job";
  EXPECT_TRUE(all_of<ab::ReqLine>(rig.take()).empty()) << "nothing is asked after the last line";
  ASSERT_EQ(rig.rows.size(), 3u) << "the blank finishing pass is not recorded";
  for (size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rig.rows[i].needles, rows[i]);
    EXPECT_EQ(rig.rows[i].number, static_cast<int>(i + 1));
    EXPECT_FALSE(rig.rows[i].stale);
  }
  // The fourth pass ended moving left: the knitter takes the carriage over the left turn mark.
  ASSERT_TRUE(rig.run_until([&] { return rig.fw.state() == ab::FsmState::ready; }));
  EXPECT_EQ(only<ab::IndState>(rig.take()).state, ab::FsmState::init);

  // A second job: reqInit is refused (not in wait-for-machine), reqStart takes no reqLine(0)
  // with it; the carriage knits one pass of the blank buffer, whose end asks for line 0.
  rig.send(ab::ReqInit{ab::MachineType::kh930});
  EXPECT_EQ(only<ab::CnfInit>(rig.take()).error, ab::err::wrong_machine_state);
  rig.send(ab::ReqStart{0, 199, false, false});
  EXPECT_EQ(only<ab::CnfStart>(rig.take()).error, 0);
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  EXPECT_EQ(all_of<ab::ReqLine>(rig.take()).at(0).line, 0);
  ASSERT_EQ(rig.rows.size(), 4u);
  EXPECT_EQ(rig.rows[3].needles, std::string(200, '0')) << "the blank pass is a pass over the needles";
  EXPECT_EQ(rig.rows[3].number, 4);
}

TEST(KnitEmuKnitting, WithNoLineTheNextPassKnitsTheOldBufferAndNothingIsAsked) {
  Rig rig(opts());
  rig.make_ready();
  rig.start(0, 3);
  rig.send(rig.line(0, "1100"));
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  rig.take();
  // The host never answers reqLine(1). The knitter, hearing no beep, pushes after its patience;
  // after two such passes it waits for a beep.
  rig.run_until([] { return false; });
  ASSERT_EQ(rig.rows.size(), 3u);
  for (size_t i = 1; i < 3; ++i) {
    EXPECT_EQ(rig.rows[i].needles, "1100") << "the old line again";
    EXPECT_TRUE(rig.rows[i].stale);
  }
  EXPECT_TRUE(rig.take().empty()) << "the firmware never asks again";
  rig.send(rig.line(1, "0011"));
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  EXPECT_EQ(all_of<ab::ReqLine>(rig.take()).at(0).line, 2);
  EXPECT_EQ(rig.rows.at(3).needles, "0011");
}

TEST(KnitEmuKnitting, TheKnitterPushesPauseMsAfterTheBeepAndAPassTakesRowMs) {
  FirmwareOptions o = opts(ab::MachineType::kh930, 200);
  o.faults.knitter_pause_ms = 15;
  Rig rig(o);
  rig.make_ready();
  rig.start(0, 9);
  rig.run_until([] { return false; }, 300);
  EXPECT_FALSE(rig.fw.carriage_moving()) << "no line, no beep: the knitter waits (patience 400 ms)";
  rig.send(rig.line(0, "1"));
  rig.advance(14);
  EXPECT_FALSE(rig.fw.carriage_moving());
  rig.advance(1);
  EXPECT_TRUE(rig.fw.carriage_moving()) << "pushed 15 ms after the beep";
  rig.advance(199);
  EXPECT_TRUE(rig.fw.carriage_moving());
  rig.advance(1);
  EXPECT_FALSE(rig.fw.carriage_moving()) << "the pass took row-ms";
}

TEST(KnitEmuKnitting, APatientKnitterPushesAfterPatienceMsWithNoBeepButStartsAJobOnlyOnOne) {
  FirmwareOptions o = opts(ab::MachineType::kh930, 100);
  o.faults.knitter_patience_ms = 300;
  Rig rig(o);
  rig.make_ready();
  rig.start(0, 9);
  rig.advance(1000);
  EXPECT_FALSE(rig.fw.carriage_moving()) << "the first pass of a job waits for the beep";
  rig.send(rig.line(0, "11"));
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  ASSERT_TRUE(rig.run_until([&] { return !rig.fw.carriage_moving(); }));
  rig.advance(299);
  EXPECT_FALSE(rig.fw.carriage_moving());
  rig.advance(1);
  EXPECT_TRUE(rig.fw.carriage_moving()) << "no line 1, no beep: pushed after 300 ms";
  ASSERT_TRUE(rig.run_until([&] { return rig.rows.size() == 2; }));
  EXPECT_EQ(rig.rows[1].needles, "1100000000") << "line 0 again";
  EXPECT_TRUE(rig.rows[1].stale);
}

TEST(KnitEmuKnitting, AnImpatientKnitterKnitsTheOldBufferWhenTheHostIsSlow) {
  FirmwareOptions o = opts(ab::MachineType::kh930, 100);
  o.faults.impatient_knitter = true;
  o.faults.knitter_pause_ms = 5;
  Rig rig(o);
  rig.make_ready();
  rig.start(0, 3);
  rig.send(rig.line(0, "1010"));
  ASSERT_TRUE(rig.run_until_sent<ab::ReqLine>());
  rig.take();
  ASSERT_TRUE(rig.run_until([&] { return !rig.fw.carriage_moving(); }));
  const int64_t rested = rig.t;
  ASSERT_TRUE(rig.run_until([&] { return rig.fw.carriage_moving(); }));
  EXPECT_EQ(rig.t - rested, 5) << "pushed 5 ms after the end of the previous pass";
  // The host is slow: its line 1 comes only after the pass has gone over the needles.
  ASSERT_TRUE(rig.run_until([&] { return rig.rows.size() == 2; }));
  EXPECT_EQ(rig.rows[1].needles, "1010") << "the old line knitted again";
  EXPECT_TRUE(rig.rows[1].stale);
  rig.send(rig.line(1, "0101"));
  ASSERT_TRUE(rig.run_until([&] { return rig.rows.size() == 3; }));
  EXPECT_EQ(rig.rows[2].needles, "0101") << "line 1 is knitted one pass late";
}

}  // namespace
}  // namespace atelier::knit_emu::testing
