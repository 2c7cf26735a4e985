// GRBL 1.1h's output lines (drivers/grbl/messages.h): classification, status reports (MPos,
// WPos+WCO), [OPT:], $n=.
#include <gtest/gtest.h>

#include "drivers/grbl/messages.h"

namespace atelier::grbl {
namespace {

using namespace std::string_view_literals;

TEST(GrblMessages, ClassifiesEveryKindOfLine) {
  EXPECT_EQ(classify("ok").kind, Reply::ok);
  const Reply e = classify("error:33");
  EXPECT_EQ(e.kind, Reply::error);
  EXPECT_EQ(e.code, 33);
  const Reply a = classify("ALARM:3");
  EXPECT_EQ(a.kind, Reply::alarm);
  EXPECT_EQ(a.code, 3);
  const Reply b = classify("Grbl 1.1h ['$' for help]");
  EXPECT_EQ(b.kind, Reply::banner);
  EXPECT_EQ(b.text, "1.1h");
  // Boot noise before the banner on the same line still finds it.
  EXPECT_EQ(classify("\xff\x00Grbl 1.1f ['$' for help]"sv).kind, Reply::banner);
  EXPECT_EQ(classify("<Idle|MPos:0.000,0.000,0.000|FS:0,0>").kind, Reply::status);
  const Reply msg = classify("[MSG:'$H'|'$X' to unlock]");
  EXPECT_EQ(msg.kind, Reply::feedback);
  EXPECT_EQ(msg.text, "MSG:'$H'|'$X' to unlock");
  EXPECT_EQ(classify("[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]").kind, Reply::feedback);
  EXPECT_EQ(classify("[VER:1.1h.20190830:]").kind, Reply::feedback);
  EXPECT_EQ(classify("[OPT:V,15,128]").kind, Reply::feedback);
  const Reply s = classify("$30=1000");
  EXPECT_EQ(s.kind, Reply::setting);
  EXPECT_EQ(s.code, 30);
  EXPECT_EQ(s.text, "1000");
  EXPECT_EQ(classify(">G20G54:ok").kind, Reply::startup);
  EXPECT_EQ(classify(">G5:error:20").kind, Reply::startup);
  EXPECT_EQ(classify("$N0=").kind, Reply::other);
  EXPECT_EQ(classify("ok\r").kind, Reply::ok);  // a '\r' left over from "\r\n"
  EXPECT_EQ(classify("okay").kind, Reply::other);
}

TEST(GrblMessages, StatusWithMachinePositionAndEveryField) {
  auto s = parse_status("<Run|MPos:12.500,-3.000,0.000|Bf:12,87|Ln:42|FS:1500,750|Ov:100,100,100|A:S>");
  ASSERT_TRUE(s);
  EXPECT_EQ(s->state, "Run");
  EXPECT_EQ(s->substate, -1);
  EXPECT_DOUBLE_EQ(s->x, 12.5);
  EXPECT_DOUBLE_EQ(s->y, -3.0);
  EXPECT_FALSE(s->has_wpos);
  EXPECT_DOUBLE_EQ(s->feed, 1500);
  EXPECT_DOUBLE_EQ(s->spindle, 750);
  EXPECT_EQ(s->planner_free, 12);
  EXPECT_EQ(s->rx_free, 87);
  EXPECT_EQ(s->line, 42);
}

TEST(GrblMessages, StatusSubstatesAndTheFeedOnlyField) {
  auto h = parse_status("<Hold:0|MPos:1.000,2.000,3.000|F:0>");
  ASSERT_TRUE(h);
  EXPECT_EQ(h->state, "Hold");
  EXPECT_EQ(h->substate, 0);
  auto d = parse_status("<Door:2|MPos:0,0,0|FS:0,0>");
  ASSERT_TRUE(d);
  EXPECT_EQ(d->state, "Door");
  EXPECT_EQ(d->substate, 2);
  EXPECT_EQ(d->planner_free, -1);  // no Bf field: unknown
  EXPECT_FALSE(parse_status("Idle|MPos:0,0,0"));
  EXPECT_FALSE(parse_status("<>"));
}

TEST(GrblMessages, WorkPositionBecomesMachinePositionWithTheOffset) {
  // $10=0: WPos; GRBL adds WCO only every 10..30 reports. WPos = MPos - WCO.
  auto with = parse_status("<Idle|WPos:10.000,5.000,0.000|FS:0,0|WCO:100.000,50.000,-1.000>");
  ASSERT_TRUE(with);
  EXPECT_FALSE(with->has_wpos);
  EXPECT_DOUBLE_EQ(with->x, 110);
  EXPECT_DOUBLE_EQ(with->y, 55);
  EXPECT_DOUBLE_EQ(with->z, -1);
  ASSERT_TRUE(with->wco);

  auto without = parse_status("<Run|WPos:20.000,5.000,0.000|FS:600,0>");
  ASSERT_TRUE(without);
  EXPECT_TRUE(without->has_wpos);  // still work coordinates
  EXPECT_DOUBLE_EQ(without->x, 20);
  apply_wco(*without, *with->wco);  // the offset remembered from an earlier report
  EXPECT_FALSE(without->has_wpos);
  EXPECT_DOUBLE_EQ(without->x, 120);
  EXPECT_DOUBLE_EQ(without->y, 55);
}

TEST(GrblMessages, OptGivesPlannerBlocksAndReceiveBuffer) {
  EXPECT_EQ(parse_opt("[OPT:VL,15,128]"), std::make_pair(15, 128));
  EXPECT_EQ(parse_opt("[OPT:V,35,1024]"), std::make_pair(35, 1024));
  EXPECT_EQ(parse_opt("[OPT:,15,128]"), std::make_pair(15, 128));  // no option letters
  EXPECT_FALSE(parse_opt("[OPT:V]"));                               // before 1.1d: no sizes
  EXPECT_FALSE(parse_opt("[VER:1.1h.20190830:]"));
}

TEST(GrblMessages, SettingLines) {
  EXPECT_EQ(parse_setting("$30=1000.000"), std::make_pair(30, 1000.0));
  EXPECT_EQ(parse_setting("$130=400.000"), std::make_pair(130, 400.0));
  EXPECT_EQ(parse_setting("$32=1"), std::make_pair(32, 1.0));
  EXPECT_EQ(parse_setting("$0=10 (step pulse, usec)"), std::make_pair(0, 10.0));  // GRBL 0.9 style
  EXPECT_FALSE(parse_setting("$N0="));
  EXPECT_FALSE(parse_setting("$30="));
  EXPECT_FALSE(parse_setting("ok"));
}

}  // namespace
}  // namespace atelier::grbl
