// Where a job lands on the machine (drivers/grbl/machine_space.h): the machine space for
// stock GRBL 1.1h and for a HOMING_FORCE_SET_ORIGIN build, the G92 each start-from mode
// sends, and the fit check's reason, as an operator would read it before anything moves.
#include <gtest/gtest.h>

#include "drivers/grbl/machine_space.h"

namespace atelier::grbl {
namespace {

MachineInfo laser(bool homing, int dir_mask, bool force_set_origin, bool soft_limits = true) {
  MachineInfo i;
  i.settings = {{20, soft_limits ? 1.0 : 0.0}, {22, homing ? 1.0 : 0.0}, {23, double(dir_mask)},
                {130, 400}, {131, 300}, {132, 50}};
  i.homing = homing;
  i.homing_dir_mask = dir_mask;
  i.force_set_origin = force_set_origin;
  i.soft_limits = soft_limits;
  return i;
}

Status at(double x, double y) {
  Status s;
  s.state = "Idle";
  s.x = x;
  s.y = y;
  return s;
}

TEST(GrblMachineSpace, StockGrblPutsEveryHomedAxisBelowZero) {
  const MachineSpace s = machine_space(laser(true, 0b011, false));
  EXPECT_TRUE(s.homed_space);
  EXPECT_DOUBLE_EQ(s.axis[0].min, -400);
  EXPECT_DOUBLE_EQ(s.axis[0].max, 0);
  EXPECT_DOUBLE_EQ(s.axis[1].min, -300);
  EXPECT_DOUBLE_EQ(s.axis[2].min, -50);
  EXPECT_EQ(bed_corner(s), (std::array<double, 2>{-400, -300}));
}

TEST(GrblMachineSpace, ForceSetOriginPutsAnAxisHomedTowardsNegativeAboveZero) {
  // $23=3: X and Y home towards negative (front-left switches), Z towards positive.
  const MachineSpace s = machine_space(laser(true, 0b011, true));
  EXPECT_DOUBLE_EQ(s.axis[0].min, 0);
  EXPECT_DOUBLE_EQ(s.axis[0].max, 400);
  EXPECT_DOUBLE_EQ(s.axis[1].max, 300);
  EXPECT_DOUBLE_EQ(s.axis[2].min, -50);
  EXPECT_DOUBLE_EQ(s.axis[2].max, 0);
  EXPECT_EQ(bed_corner(s), (std::array<double, 2>{0, 0}));
}

TEST(GrblMachineSpace, WithoutHomingThePowerUpPositionIsTheCorner) {
  const MachineSpace s = machine_space(laser(false, 0, false, false));
  EXPECT_FALSE(s.homed_space);
  EXPECT_EQ(bed_corner(s), (std::array<double, 2>{0, 0}));
  EXPECT_DOUBLE_EQ(s.axis[0].max, 400);
}

TEST(GrblMachineSpace, StartFromNamesRoundTrip) {
  for (auto f : {StartFrom::bed, StartFrom::origin, StartFrom::here})
    EXPECT_EQ(parse_start_from(start_from_name(f)), f);
  EXPECT_FALSE(parse_start_from("front-left"));
}

TEST(GrblMachineSpace, BedPlacementMakesWorkZeroTheFrontLeftCorner) {
  // Stock space: head homed at machine (0,0) = rear right; the corner is (-400,-300), so the
  // head's work position must read (400,300).
  const MachineSpace stock = machine_space(laser(true, 0, false));
  EXPECT_EQ(placement_lines(StartFrom::bed, stock, at(0, 0), {}), std::vector<std::string>{"G92X400.000Y300.000"});
  EXPECT_EQ(placement_lines(StartFrom::bed, stock, at(-150.5, -20), {-10, -10, 0}),
            std::vector<std::string>{"G92X249.500Y280.000"});
  const MachineSpace forced = machine_space(laser(true, 3, true));
  EXPECT_EQ(placement_lines(StartFrom::bed, forced, at(12, 7), {}), std::vector<std::string>{"G92X12.000Y7.000"});
}

TEST(GrblMachineSpace, OriginSendsNothingAndHereZeroesThePosition) {
  const MachineSpace s = machine_space(laser(true, 0, false));
  EXPECT_TRUE(placement_lines(StartFrom::origin, s, at(-100, -100), {-200, -150, 0}).empty());
  EXPECT_EQ(placement_lines(StartFrom::here, s, at(-100, -100), {}), std::vector<std::string>{"G92X0Y0"});
}

TEST(GrblMachineSpace, FitCheckInEachModeMovesTheJobIntoMachineSpace) {
  const MachineInfo info = laser(true, 0, false);
  const MachineSpace s = machine_space(info);
  const Bounds job{10, 10, 120, 80};
  EXPECT_EQ(check_fits(job, StartFrom::bed, s, info, at(0, 0), {}), "");
  // Work zero 50 mm left of the rear-right home: the job would reach X +70.
  const std::string origin = check_fits(job, StartFrom::origin, s, info, at(0, 0), {-50, -200, 0});
  EXPECT_NE(origin.find("the job spans X -40.0..70.0 mm in the machine's space but the machine reaches X -400.0..0.0 mm"),
            std::string::npos)
      << origin;
  EXPECT_EQ(origin.find("spans Y"), std::string::npos);  // Y fits: only X is named
  EXPECT_NE(origin.find("start from origin"), std::string::npos);
  // The head at the rear right: a job started here runs past both far edges.
  const std::string here = check_fits(job, StartFrom::here, s, info, at(-5, -5), {});
  EXPECT_NE(here.find("X 5.0..115.0"), std::string::npos) << here;
  EXPECT_NE(here.find("Y 5.0..75.0"), std::string::npos) << here;
  EXPECT_EQ(check_fits(job, StartFrom::here, s, info, at(-300, -200), {}), "");
}

TEST(GrblMachineSpace, AJobBiggerThanTheBedIsRefusedFromTheBed) {
  const MachineInfo info = laser(true, 3, true);
  const MachineSpace s = machine_space(info);
  const std::string why = check_fits(Bounds{0, 0, 450, 100}, StartFrom::bed, s, info, at(0, 0), {});
  EXPECT_NE(why.find("X 0.0..450.0 mm in the machine's space but the machine reaches X 0.0..400.0 mm"),
            std::string::npos)
      << why;
  // On the edge exactly is inside.
  EXPECT_EQ(check_fits(Bounds{0, 0, 400, 300}, StartFrom::bed, s, info, at(0, 0), {}), "");
}

TEST(GrblMachineSpace, AnUnknownTravelIsNotChecked) {
  MachineInfo info = laser(true, 0, false);
  info.settings[131] = 0;
  const std::string why = check_fits(Bounds{0, 0, 450, 900}, StartFrom::bed, machine_space(info), info, at(0, 0), {});
  EXPECT_NE(why.find("spans X"), std::string::npos) << why;
  EXPECT_EQ(why.find("spans Y"), std::string::npos) << why;
}

TEST(GrblMachineSpace, SoftLimitsOffMeansNoCheck) {
  const MachineInfo info = laser(true, 0, false, false);
  EXPECT_EQ(check_fits(Bounds{0, 0, 9000, 9000}, StartFrom::bed, machine_space(info), info, at(0, 0), {}), "");
}

}  // namespace
}  // namespace atelier::grbl
