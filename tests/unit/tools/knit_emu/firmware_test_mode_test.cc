// The firmware model's hardware test mode (reqTest and the test commands), as AYAB firmware
// 1.0.0's tester.cpp, com.cpp and fsm.cpp do it.
#include <gtest/gtest.h>

#include "tests/support/knit_emu_rig.h"

namespace atelier::knit_emu::testing {
namespace {

std::vector<std::string> texts(const std::vector<ab::Message>& msgs) {
  std::vector<std::string> out;
  for (const auto& t : all_of<ab::TestRes>(msgs)) out.push_back(t.text);
  return out;
}

const std::vector<std::string> kHelp = {
    "The following commands are available:\n", "setSingle [0..15] [1/0]\n", "setAll [0..FFFF]\n",
    "readEOLsensors\n", "readEncoders\n", "beep\n", "autoRead\n", "autoTest\n", "send\n", "stop\n", "quit\n", "help\n"};

TEST(KnitEmuTestMode, ReqTestSendsTheTesterTextsThenCnfTestAndEntersTest) {
  Rig rig(opts());
  rig.send(ab::ReqTest{});
  const ab::Bytes raw = rig.fw.take_output();
  const auto packets = ab::SlipDecoder{}.feed(raw);
  ASSERT_FALSE(packets.empty());
  const std::string first = "AYAB Hardware Test, ";
  ab::Bytes want = {0xEE};
  want.insert(want.end(), first.begin(), first.end());
  EXPECT_EQ(packets.front(), want) << "testRes is the id and the characters, no NUL";
  std::vector<ab::Message> msgs;
  for (const auto& p : packets) msgs.push_back(*ab::decode(p, 25).message);
  std::vector<std::string> expected = {"AYAB Hardware Test, ", "Firmware v1.0.0", " API v6\n\n"};
  expected.insert(expected.end(), kHelp.begin(), kHelp.end());
  EXPECT_EQ(texts(msgs), expected);
  EXPECT_EQ(std::get<ab::CnfTest>(msgs.back()).error, 0) << "cnfTest comes after setUp's texts";
  EXPECT_EQ(rig.fw.state(), ab::FsmState::test);
  rig.send(ab::ReqTest{});
  EXPECT_EQ(all_of<ab::CnfTest>(rig.take()).at(0).error, ab::err::wrong_machine_state) << "already testing";
}

TEST(KnitEmuTestMode, ReqTestIsTakenInInitAndReadyButNotWhileKnitting) {
  Rig init(opts());
  init.send(ab::ReqInit{ab::MachineType::kh930});
  init.take();
  init.send(ab::ReqTest{});
  EXPECT_EQ(all_of<ab::CnfTest>(init.take()).at(0).error, 0);

  Rig ready(opts());
  ready.make_ready();
  ready.send(ab::ReqTest{});
  EXPECT_EQ(all_of<ab::CnfTest>(ready.take()).at(0).error, 0);

  Rig knitting(opts());
  knitting.make_ready();
  knitting.start(0, 9);
  knitting.send(ab::ReqTest{});
  EXPECT_EQ(only<ab::CnfTest>(knitting.take()).error, ab::err::wrong_machine_state);
  EXPECT_EQ(knitting.fw.state(), ab::FsmState::knit);
}

TEST(KnitEmuTestMode, ThePositionIsFrozenInTestSoOneIndState0xFFComesOnEntering) {
  Rig rig(opts());
  rig.make_ready();  // the carriage moved since the last knitting (none): position 0 -> 34
  rig.send(ab::ReqTest{});
  auto states = all_of<ab::IndState>(rig.take());
  ASSERT_EQ(states.size(), 1u);
  EXPECT_EQ(states[0].error, 0xFF);
  EXPECT_EQ(states[0].state, ab::FsmState::test);
  EXPECT_EQ(states[0].position, Firmware::kReadyPosition);
  // The tester's encoder handler replaced the knitter's: moves are not counted any more.
  rig.fw.push_carriage(120, 100);
  rig.run_until([] { return false; });
  EXPECT_TRUE(rig.take().empty());
}

TEST(KnitEmuTestMode, QuitGoesToWaitForMachineAndKeepsTheFirstRunSpent) {
  Rig rig(opts(ab::MachineType::kh930, 20));
  rig.make_ready();
  rig.start(0, 7);
  rig.knit_job({"1"});
  rig.take();
  rig.send(ab::ReqTest{});
  rig.take();
  rig.send_payload({0x2F});  // quitCmd
  EXPECT_EQ(rig.fw.state(), ab::FsmState::wait_for_machine);
  EXPECT_TRUE(rig.take().empty());
  rig.make_ready();
  rig.send(ab::ReqStart{0, 7, false, false});
  // quitCmd sets wait-for-machine, and fsm.cpp calls Knitter::init (m_firstRun = true) only
  // on a way to init: the next job still starts with a blank pass.
  EXPECT_EQ(only<ab::CnfStart>(rig.take()).error, 0);
}

TEST(KnitEmuTestMode, TestCommandsAreHandledInEveryState) {
  Rig rig(opts());
  rig.send_payload({0x25});  // helpCmd in wait-for-machine
  EXPECT_EQ(texts(rig.take()), kHelp);
  rig.send_payload({0x2A});  // readEOLsensors
  EXPECT_EQ(texts(rig.take()),
            (std::vector<std::string>{"Called readEOLsensors\n", "  EOL_L: 440", "  EOL_R: 358", "\n"}));
  rig.send_payload({0x28, 16, 1});
  EXPECT_EQ(texts(rig.take()),
            (std::vector<std::string>{"Called setSingle\n", "Error: invalid solenoid index 16\n"}));
}

TEST(KnitEmuTestMode, AutoReadReportsEverySecondTimerEventUntilStop) {
  Rig rig(opts());
  rig.send(ab::ReqTest{});
  rig.take();
  rig.send_payload({0x2C});
  EXPECT_EQ(texts(rig.take()), (std::vector<std::string>{"Called autoRead, send stop to quit\n"}));
  rig.advance(500);
  EXPECT_TRUE(rig.take().empty()) << "the first 500 ms event is an even one";
  rig.advance(500);
  EXPECT_EQ(texts(rig.take()), (std::vector<std::string>{"\n", "  EOL_L: 440", "  EOL_R: 358", "  ENC_A: ", "LOW",
                                                         "  ENC_B: ", "LOW", "  ENC_C: ", "LOW", "\n"}));
  rig.send_payload({0x2E});
  rig.advance(2000);
  EXPECT_TRUE(rig.take().empty());
  EXPECT_EQ(rig.fw.next_event_ms(), std::nullopt);
}

}  // namespace
}  // namespace atelier::knit_emu::testing
