// The GRBL 1.1h laser controller model (tools/laser_emu/controller.h), in virtual time: the line
// protocol ($ commands, filtering, check mode, alarm lock), the serial side (baud rate, 128-byte
// buffer) and the DTR line (a host that goes away restarts the board, beam off at once).
#include <gtest/gtest.h>

#include <deque>

#include "tests/support/laser_emu_rig.h"

namespace atelier::laser_emu {
namespace {

using testing::Rig;

TEST(LaserEmuProtocol, BannerAtPowerOnPacedAtTheBaudRate) {
  Rig rig;
  rig.run(1000);  // 1 ms: at 86.8 us per byte only 11 of the banner's 29 bytes are out
  EXPECT_EQ(rig.out.size(), 11u);
  rig.run(5000);
  EXPECT_EQ(rig.take(), "\r\nGrbl 1.1h ['$' for help]\r\n");
  EXPECT_EQ(rig.ctl.state_name(), "Idle");
}

TEST(LaserEmuProtocol, BuildInfoAndSettings) {
  Rig rig;
  rig.boot();
  EXPECT_EQ(rig.exchange("$I"), "[VER:1.1h.20190830:]\r\n[OPT:V,15,128]\r\nok\r\n");
  const std::string settings = rig.exchange("$$");
  EXPECT_EQ(settings.rfind("$0=10\r\n$1=25\r\n", 0), 0u) << settings;
  // DEFAULTS_GENERIC, but for what a laser owner stores (laser mode, work area, motion).
  for (const char* line : {"$10=1\r\n", "$20=0\r\n", "$22=0\r\n", "$23=0\r\n", "$27=1.000\r\n", "$132=200.000\r\n", "$30=1000\r\n", "$31=0\r\n", "$32=1\r\n",
                           "$110=6000.000\r\n", "$120=500.000\r\n", "$130=400.000\r\n", "$131=400.000\r\n"})
    EXPECT_NE(settings.find(line), std::string::npos) << line;
  EXPECT_EQ(settings.substr(settings.size() - 4), "ok\r\n");
  EXPECT_EQ(rig.exchange("$G"), "[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]\r\nok\r\n");
  EXPECT_EQ(rig.exchange("$N"), "$N0=\r\n$N1=\r\nok\r\n");
  EXPECT_EQ(rig.exchange("$"), "[HLP:$$ $# $G $I $N $x=val $Nx=line $J=line $SLP $C $X $H ~ ! ? ctrl-x]\r\nok\r\n");
}

TEST(LaserEmuProtocol, ToolNumbersStartupIndexesAndReportUnitsAsTheRealOne) {
  Rig rig;
  rig.boot();
  // gc_state.tool takes every executed line's T: 0 again after a line without one.
  ASSERT_EQ(rig.exchange("T1"), "ok\r\n");
  EXPECT_EQ(rig.exchange("$G"), "[GC:G0 G54 G17 G21 G90 G94 M5 M9 T1 F0 S0]\r\nok\r\n");
  ASSERT_EQ(rig.exchange("G21"), "ok\r\n");
  EXPECT_EQ(rig.exchange("$G"), "[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]\r\nok\r\n");
  EXPECT_EQ(rig.exchange("T1.5"), "ok\r\n");
  EXPECT_EQ(rig.exchange("M6"), "error:20\r\n");
  // $G prints F in the units of $13, not of G20.
  ASSERT_EQ(rig.exchange("G20 F10"), "ok\r\n");
  EXPECT_EQ(rig.exchange("$G"), "[GC:G0 G54 G17 G20 G90 G94 M5 M9 T0 F254 S0]\r\nok\r\n");
  ASSERT_EQ(rig.exchange("$13=1"), "ok\r\n");
  EXPECT_EQ(rig.exchange("$G"), "[GC:G0 G54 G17 G20 G90 G94 M5 M9 T0 F10.0 S0]\r\nok\r\n");
  // $N2= and up: checked and answered (GRBL writes past the two slots), never listed or run.
  EXPECT_EQ(rig.exchange("$N2=G0"), "ok\r\n");
  EXPECT_EQ(rig.exchange("$N2=Q5"), "error:20\r\n");
  EXPECT_EQ(rig.exchange("$N"), "$N0=\r\n$N1=\r\nok\r\n");
}

TEST(LaserEmuProtocol, ProgramEndRefreshesTheWorkOffsetInTheNextReport) {
  Rig rig;
  rig.boot();
  for (int i = 0; i < 3; ++i) {  // past the session's first WCO and Ov reports
    rig.send("?");
    rig.run(10'000);
  }
  rig.take();
  ASSERT_EQ(rig.exchange("M2"), "[MSG:Pgm End]\r\nok\r\n");
  rig.send("?");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "<Idle|MPos:0.000,0.000,0.000|FS:0,0|WCO:0.000,0.000,0.000>\r\n");
}

TEST(LaserEmuProtocol, LinesLongerThanTheLineBufferAreError11) {
  Rig rig;
  rig.boot();
  EXPECT_EQ(rig.exchange("G0X" + std::string(76, '0')), "ok\r\n");         // 79 characters fit
  EXPECT_EQ(rig.exchange("G0X" + std::string(77, '0')), "error:11\r\n");   // 80 do not
  // Spaces and comments do not count.
  EXPECT_EQ(rig.exchange("G0 X1 " + std::string(100, ' ') + "(" + std::string(100, 'c') + ")"), "ok\r\n");
}

TEST(LaserEmuProtocol, FilteringCommentsCaseAndLineEnds) {
  Rig rig;
  rig.boot();
  EXPECT_EQ(rig.exchange("g21 (millimetres) g90 ; absolute"), "ok\r\n");
  EXPECT_EQ(rig.exchange("(just a comment)"), "ok\r\n");
  EXPECT_EQ(rig.exchange(""), "ok\r\n");
  rig.send("G21\r\n");  // CR and LF each end a line, as in protocol.c
  rig.run(5000);
  EXPECT_EQ(rig.take(), "ok\r\nok\r\n");
  EXPECT_EQ(rig.ctl.lines_received(), 5);
}

TEST(LaserEmuProtocol, CheckModeParsesWithoutMotionAndLeavesWithAReset) {
  Rig rig;
  rig.boot();
  EXPECT_EQ(rig.exchange("$C"), "[MSG:Enabled]\r\nok\r\n");
  EXPECT_EQ(rig.ctl.state(), MachineState::check);
  EXPECT_EQ(rig.exchange("G1 X50 Y20 F1000 M4 S800"), "ok\r\n");
  EXPECT_EQ(rig.exchange("G1 X10"), "ok\r\n");
  EXPECT_EQ(rig.exchange("G1 Q1"), "error:20\r\n");
  rig.send("?");
  rig.run(10000);
  EXPECT_EQ(rig.take().rfind("<Check|MPos:0.000,0.000,0.000|FS:0,0", 0), 0u);
  EXPECT_EQ(rig.ctl.planner_blocks(), 0);
  EXPECT_TRUE(rig.record.segments.empty());
  EXPECT_EQ(rig.exchange("$C"), "[MSG:Disabled]\r\nok\r\n");
  rig.run(5000);
  EXPECT_EQ(rig.take(), "\r\nGrbl 1.1h ['$' for help]\r\n");
  EXPECT_EQ(rig.ctl.state(), MachineState::idle);
  EXPECT_EQ(rig.exchange("$G"), "[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]\r\nok\r\n");  // parser reset
}

TEST(LaserEmuProtocol, UnlockAndCheckModeNeedTheRightState) {
  ControllerOptions o;
  o.alarm_at_line = 2;  // a hard limit while line 2 runs
  Rig rig(o);
  rig.boot();
  EXPECT_EQ(rig.exchange("$X"), "ok\r\n");  // no alarm: no effect
  rig.send("G0 X-5\n");
  ASSERT_TRUE(rig.run_until("[MSG:Reset to continue]\r\n"));
  rig.send("\x18");
  ASSERT_TRUE(rig.run_until("[MSG:'$H'|'$X' to unlock]\r\n"));
  rig.take();
  EXPECT_EQ(rig.exchange("$C"), "error:8\r\n");
  EXPECT_EQ(rig.exchange("G0 X1"), "error:9\r\n");
  EXPECT_EQ(rig.exchange("$I").substr(0, 5), "[VER:");  // $ commands work in Alarm
  EXPECT_EQ(rig.exchange("$X"), "[MSG:Caution: Unlocked]\r\nok\r\n");
  EXPECT_EQ(rig.exchange("G0 X1"), "ok\r\n");
}

TEST(LaserEmuProtocol, SleepStopsEverythingUntilAResetThatComesBackLocked) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("G1 F100 M3 S300"), "ok\r\n");  // M3 in G1 mode: lit at rest
  EXPECT_GT(rig.ctl.laser_s(), 0.0);
  EXPECT_EQ(rig.exchange("$SLP"), "ok\r\n");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "[MSG:Sleeping]\r\n");
  EXPECT_EQ(rig.ctl.laser_s(), 0.0);  // spindle_set_state(SPINDLE_DISABLE)
  rig.send("G0 X-5\n?");
  rig.run(100'000);
  EXPECT_EQ(rig.take().rfind("<Sleep|MPos:0.000,0.000,0.000|", 0), 0u);  // only "?" is answered
  rig.send("\x18");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "\r\nGrbl 1.1h ['$' for help]\r\n[MSG:'$H'|'$X' to unlock]\r\n");
  EXPECT_EQ(rig.ctl.state(), MachineState::alarm);
  EXPECT_EQ(rig.exchange("$SLPX"), "error:3\r\n");
}

constexpr double kByteUs = 1e6 * 10 / 115200;  // 86.8 us

// Fills the planner with 15 slow moves (each 100 s long) and waits until all are answered.
void fill_planner(Rig& rig) {
  rig.exchange("G1 F60");
  for (int i = 1; i <= 15; ++i) {
    ASSERT_EQ(rig.exchange("G1 X" + std::to_string(i % 2 ? 100 : 0)), "ok\r\n") << i;
  }
  ASSERT_EQ(rig.ctl.planner_blocks(), 15);
}

TEST(LaserEmuSerial, BytesArriveAtTheBaudRate) {
  Rig rig;
  rig.boot();
  rig.send("$I\n");  // 3 bytes: the first arrives at once, the newline two byte times later
  rig.run(static_cast<int64_t>(1.5 * kByteUs));
  EXPECT_EQ(rig.ctl.lines_received(), 0);
  rig.run(static_cast<int64_t>(kByteUs));
  EXPECT_EQ(rig.ctl.lines_received(), 1);
  // The 41-byte answer takes 41 byte times to leave.
  rig.run(static_cast<int64_t>(30 * kByteUs));
  EXPECT_LT(rig.out.size(), 41u);
  rig.run(static_cast<int64_t>(15 * kByteUs));
  EXPECT_EQ(rig.take(), "[VER:1.1h.20190830:]\r\n[OPT:V,15,128]\r\nok\r\n");
}

TEST(LaserEmuSerial, PlannerFullStopsTheMainLoopAndTheReceiveBufferFills) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("$10=3"), "ok\r\n");  // MPos and the Bf: field
  fill_planner(rig);
  rig.send("G1 X50\nG1 X60\n");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "");  // no ok: the main loop waits for a free planner block
  EXPECT_EQ(rig.ctl.rx_used(), 7);  // the second line stays in the receive buffer
  EXPECT_EQ(rig.ctl.planner_blocks(), 15);
  // Real-time bytes bypass the buffer: a status report comes at once.
  rig.send("?");
  rig.run(10'000);  // the report is 58 bytes: 5 ms on the wire
  const std::string status = rig.take();
  EXPECT_EQ(status.rfind("<Run|MPos:", 0), 0u) << status;
  EXPECT_NE(status.find("|Bf:0,120|"), std::string::npos) << status;  // 127 - 7 bytes free
  // The first move (100 mm at 60 mm/min) ends after 100 s: one block frees, one line goes in.
  rig.run(100'000'000);
  EXPECT_EQ(rig.take(), "ok\r\n");
  EXPECT_EQ(rig.ctl.planner_blocks(), 15);
}

TEST(LaserEmuSerial, TwoHundredBytesAtOnceOverflowTheReceiveBuffer) {
  Rig rig;
  rig.boot();
  fill_planner(rig);
  // 200 bytes at once: the first line waits for the planner, the rest pile up.
  rig.send("G1 X50\n" + std::string(193, ' '));
  rig.run(50'000);
  EXPECT_EQ(rig.ctl.rx_used(), 127);
  EXPECT_EQ(rig.record.max_rx_bytes, 127);
  EXPECT_EQ(rig.record.rx_overflows, 193 - 127);
  ASSERT_FALSE(rig.record.events.empty());
  const Event& e = rig.record.events.back();
  EXPECT_EQ(e.event, "overflow");
  EXPECT_EQ(e.line, 18);  // 16 lines answered, the 17th waiting, the 18th cut
}

TEST(LaserEmuSerial, CharacterCountingWithin127BytesNeverOverflows) {
  ControllerOptions o;
  o.time_scale = 0.2;
  Rig rig(o);
  rig.boot();
  // A character-counting host: at most 127 bytes of unanswered lines in flight.
  std::deque<size_t> in_flight;
  size_t used = 0;
  int next = 0, answered = 0;
  constexpr int kLines = 300;
  auto line = [](int i) {
    return "G1 X" + std::to_string(10 + i % 7) + "." + std::to_string(i % 10) + " Y" + std::to_string(5 + i % 3) +
           (i == 0 ? " F3000 M4 S300" : " S" + std::to_string(100 + i % 900)) + "\n";
  };
  for (int64_t step = 0; answered < kLines && step < 2'000'000; ++step) {
    while (next < kLines && used + line(next).size() <= 127) {
      const std::string l = line(next++);
      rig.send(l);
      in_flight.push_back(l.size());
      used += l.size();
    }
    rig.run(100);
    for (size_t at; (at = rig.out.find("\r\n")) != std::string::npos;) {
      const std::string reply = rig.out.substr(0, at);
      rig.out.erase(0, at + 2);
      if (reply == "ok" || reply.rfind("error:", 0) == 0) {
        ASSERT_EQ(reply, "ok");
        ASSERT_FALSE(in_flight.empty());
        used -= in_flight.front();
        in_flight.pop_front();
        ++answered;
      }
    }
  }
  EXPECT_EQ(answered, kLines);
  EXPECT_EQ(rig.record.rx_overflows, 0);
  EXPECT_GT(rig.record.max_rx_bytes, 90);  // the buffer was really used
  EXPECT_LE(rig.record.max_rx_bytes, 127);
}

TEST(LaserEmuSerial, ResetFlushesTheReceiveBufferAndThePlanner) {
  Rig rig;
  rig.boot();
  fill_planner(rig);
  rig.send("G1 X5\nG1 X6\n");
  rig.run(5'000);
  rig.send("\x18");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "ALARM:3\r\n");
  rig.run(500'000);  // report_alarm_message()'s delay; X5 was waiting for the planner: its ok
  EXPECT_EQ(rig.take(), "ok\r\n\r\nGrbl 1.1h ['$' for help]\r\n[MSG:'$H'|'$X' to unlock]\r\n");
  EXPECT_EQ(rig.ctl.rx_used(), 0);
  EXPECT_EQ(rig.ctl.planner_blocks(), 0);
}

TEST(LaserEmuSerial, HaltAfterLineStopsListeningButFinishesTheAnswerAndTheMotion) {
  ControllerOptions o;
  o.halt_after_line = 2;
  Rig rig(o);
  rig.boot();
  rig.send("G1 X10 F600\nG1 X20\nG1 X30\n?");
  rig.run(100'000);
  EXPECT_EQ(rig.take(), "ok\r\nok\r\n");  // line 3 and the status request go unanswered
  EXPECT_TRUE(rig.ctl.halted());
  rig.run(3'000'000);
  EXPECT_EQ(rig.ctl.position()[0], 20.0);  // the planned moves still run out
  EXPECT_EQ(rig.ctl.lines_received(), 2);
}

constexpr const char* kBanner = "\r\nGrbl 1.1h ['$' for help]\r\n";

TEST(LaserEmuDtr, AHangupMidJobRestartsTheBoardAtOnceWithTheBeamOff) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("M3 S800"), "ok\r\n");
  fill_planner(rig);                // 15 moves of 100 mm at 60 mm/min: minutes of burning queued
  rig.send("G1 X5\nG1 X6\n");      // and more waiting in the receive buffer
  rig.run(500'000);
  rig.take();
  ASSERT_EQ(rig.ctl.state_name(), "Run");
  ASSERT_GT(rig.ctl.laser_s(), 0);
  const double hangup_s = static_cast<double>(rig.t) * 1e-6;

  rig.ctl.hangup(rig.t);
  EXPECT_EQ(rig.ctl.laser_s(), 0);
  EXPECT_EQ(rig.ctl.state_name(), "Idle");  // homing is off ($22=0)
  EXPECT_EQ(rig.ctl.planner_blocks(), 0);
  EXPECT_EQ(rig.ctl.rx_used(), 0);
  EXPECT_EQ(rig.ctl.position(), (Vec3{0, 0, 0})) << "a restarted board starts at its power-up position";
  rig.run(3'000'000);
  EXPECT_EQ(rig.take(), "") << "the banner waits for the next host";

  const Record r = rig.ctl.snapshot();
  for (const Segment& seg : r.segments)
    if (seg.power > 0) EXPECT_LE(seg.t1, hangup_s + 1e-9) << "burned after the hangup";
  ASSERT_GE(r.events.size(), 2u);
  const Event& hangup = r.events[r.events.size() - 2];
  const Event& beam_off = r.events.back();
  EXPECT_EQ(hangup.event, "hangup");
  EXPECT_EQ(beam_off.event, "beam_off");
  EXPECT_DOUBLE_EQ(beam_off.t, hangup.t);

  rig.ctl.host_connected(rig.t);
  rig.run(10'000);
  EXPECT_EQ(rig.take(), kBanner);
  EXPECT_EQ(rig.exchange("G1 X1 F600"), "ok\r\n");  // takes G-code again, from a fresh parser
}

TEST(LaserEmuDtr, WithHomingEnabledTheRestartedBoardComesBackLockedInAlarm) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("$22=1"), "ok\r\n");
  rig.ctl.hangup(rig.t);
  rig.ctl.host_connected(rig.t);
  rig.run(20'000);
  EXPECT_EQ(rig.take(), std::string(kBanner) + "[MSG:'$H'|'$X' to unlock]\r\n");
  EXPECT_EQ(rig.ctl.state_name(), "Alarm");
  EXPECT_EQ(rig.exchange("G1 X1 F600"), "error:9\r\n");
  EXPECT_EQ(rig.exchange("$$").find("$22=1\r\n") != std::string::npos, true) << "settings live in EEPROM";
}

TEST(LaserEmuDtr, ThePowerOnBannerCanWaitForTheFirstHost) {
  ControllerOptions o;
  o.banner_waits_for_host = true;
  Rig rig(o);
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "");
  rig.ctl.host_connected(rig.t);
  rig.run(10'000);
  EXPECT_EQ(rig.take(), kBanner);
  rig.ctl.host_connected(rig.t);  // a host seen again without a hangup: no second banner
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "");
}

}  // namespace
}  // namespace atelier::laser_emu
