// GRBL's global settings in the laser emulator (tools/laser_emu/settings.h): the work area as
// soft limits, and values stored with GRBL's checks.
#include <gtest/gtest.h>

#include "tests/support/laser_emu_rig.h"

namespace atelier::laser_emu {
namespace {

using testing::Rig;

TEST(LaserEmuProtocol, WorkAreaBecomesTheSoftLimits) {
  ControllerOptions o;
  o.work_w_mm = 300;
  o.work_h_mm = 200;
  Rig rig(o);
  rig.boot();
  const std::string settings = rig.exchange("$$");
  EXPECT_NE(settings.find("$130=300.000\r\n$131=200.000\r\n"), std::string::npos);
}

TEST(LaserEmuProtocol, SettingsAreStoredWithGrblsChecks) {
  Rig rig;
  rig.boot();
  EXPECT_EQ(rig.exchange("$10=3"), "ok\r\n");
  EXPECT_NE(rig.exchange("$$").find("$10=3\r\n"), std::string::npos);
  EXPECT_EQ(rig.exchange("$100=-5"), "error:4\r\n");
  EXPECT_EQ(rig.exchange("$0=2"), "error:6\r\n");
  EXPECT_EQ(rig.exchange("$20=1"), "error:10\r\n");  // soft limits need homing ($22)
  EXPECT_EQ(rig.exchange("$7=1"), "error:3\r\n");
  EXPECT_EQ(rig.exchange("$300=1"), "error:3\r\n");
  EXPECT_EQ(rig.exchange("$$$"), "error:3\r\n");
  EXPECT_EQ(rig.exchange("$H"), "error:5\r\n");  // homing disabled
  EXPECT_EQ(rig.exchange("$22=1"), "ok\r\n");
  EXPECT_EQ(rig.exchange("$20=1"), "ok\r\n");
  EXPECT_EQ(rig.exchange("$H", 60'000'000), "ok\r\n");
}

TEST(LaserEmuProtocol, RestoringDefaultsGivesGrblsCompiledDefaults) {
  Rig rig;
  rig.boot();
  ASSERT_EQ(rig.exchange("$N0=G21"), "ok\r\n");
  ASSERT_EQ(rig.exchange("$I=MYLASER"), "ok\r\n");
  EXPECT_EQ(rig.exchange("$RST=#"), "[MSG:Restoring defaults]\r\nok\r\n");  // offsets only
  ASSERT_TRUE(rig.run_until(">G21:ok\r\n"));
  rig.take();
  EXPECT_NE(rig.exchange("$$").find("$32=1\r\n"), std::string::npos);
  EXPECT_EQ(rig.exchange("$RST=$"), "[MSG:Restoring defaults]\r\nok\r\n");
  ASSERT_TRUE(rig.run_until(">G21:ok\r\n"));  // startup lines are kept
  rig.take();
  const std::string settings = rig.exchange("$$");
  // defaults.h DEFAULTS_GENERIC: no laser mode, 200 mm travel, 500 mm/min, 10 mm/s^2.
  for (const char* line : {"$20=0\r\n", "$22=0\r\n", "$32=0\r\n", "$100=250.000\r\n", "$110=500.000\r\n",
                           "$120=10.000\r\n", "$130=200.000\r\n", "$131=200.000\r\n"})
    EXPECT_NE(settings.find(line), std::string::npos) << line;
  EXPECT_EQ(rig.exchange("$I"), "[VER:1.1h.20190830:MYLASER]\r\n[OPT:V,15,128]\r\nok\r\n");
  EXPECT_EQ(rig.exchange("$RST=*"), "[MSG:Restoring defaults]\r\nok\r\n");
  rig.run(10'000);
  EXPECT_EQ(rig.take(), "\r\nGrbl 1.1h ['$' for help]\r\n");
  EXPECT_EQ(rig.exchange("$I"), "[VER:1.1h.20190830:]\r\n[OPT:V,15,128]\r\nok\r\n");
  EXPECT_EQ(rig.exchange("$RST=x"), "error:3\r\n");
}

// Undefined behaviour UBSan reports through fuzz_laser_emu_gcode
// (tests/fuzz/regressions/laser_emu_gcode/huge-setting-numbers): huge numbers
// were cast to int: "$10=25600000000" was then listed as "$10=-2147483648".
TEST(LaserEmuProtocol, IntegerSettingsKeepAByteAndSettingNumbersAreInRange) {
  Rig rig;
  rig.boot();
  EXPECT_EQ(rig.exchange("$10=300"), "ok\r\n");
  EXPECT_NE(rig.exchange("$$").find("$10=44\r\n"), std::string::npos);  // 300 in a uint8
  EXPECT_EQ(rig.exchange("$10=25600000000"), "ok\r\n");
  EXPECT_NE(rig.exchange("$$").find("$10=0\r\n"), std::string::npos);   // 2.56e10 = 10^8 * 256
  EXPECT_EQ(rig.exchange("$-99999999999=1"), "error:3\r\n");
  EXPECT_EQ(rig.exchange("$-1=1"), "error:3\r\n");
}

}  // namespace
}  // namespace atelier::laser_emu
