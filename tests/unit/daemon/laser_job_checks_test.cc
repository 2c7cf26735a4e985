// Checks made before a laser job is sent: the power scale it was made for and the travel.
#include <gtest/gtest.h>

#include "daemon/laser_job_checks.h"

using atelier::job_fit_problem;
using atelier::rapid_rate;
namespace grbl = atelier::grbl;

namespace {

grbl::MachineInfo controller(double s_max, double travel_x, double travel_y) {
  grbl::MachineInfo info;
  info.s_max = s_max;
  info.max_travel_x = travel_x;
  info.max_travel_y = travel_y;
  return info;
}

grbl::Program job(const std::string& header, const std::string& moves) {
  return grbl::parse_program(header + "G21 G90\n" + moves + "M5\n", 6000);
}

}  // namespace

TEST(LaserJobChecks, AJobInsideTheTravelWithTheSamePowerScaleFits) {
  auto p = job("; s_max=1000\n", "G0 X10 Y10\nG1 X390 Y10 F600 S800\nG1 X390 Y395\n");
  EXPECT_EQ(job_fit_problem(p, controller(1000, 400, 400), "job.gcode"), std::nullopt);
}

TEST(LaserJobChecks, ADifferentPowerScaleIsRefusedWithTheSettingToChange) {
  auto p = job("; s_max=1000\n", "G1 X10 Y10 F600 S800\n");
  auto problem = job_fit_problem(p, controller(255, 400, 400), "job.gcode");
  ASSERT_TRUE(problem);
  EXPECT_NE(problem->find("job.gcode"), std::string::npos) << *problem;
  EXPECT_NE(problem->find("$30 is 255"), std::string::npos) << *problem;
  EXPECT_NE(problem->find("s_max = 255"), std::string::npos) << *problem;
}

TEST(LaserJobChecks, AJobBeyondTheTravelIsRefusedWithBothSizes) {
  auto p = job("", "G0 X10 Y10\nG1 X450 Y10 F600 S800\n");
  auto problem = job_fit_problem(p, controller(1000, 400, 300), "cuts.gcode");
  ASSERT_TRUE(problem);
  EXPECT_NE(problem->find("X 10.0..450.0"), std::string::npos) << *problem;
  EXPECT_NE(problem->find("400.0 x 300.0"), std::string::npos) << *problem;
}

TEST(LaserJobChecks, NegativeWorkspacesAreCheckedAgainstTheTravelToo) {
  auto inside = job("", "G0 X-10 Y-10\nG1 X-390 Y-290 F600 S800\n");
  EXPECT_EQ(job_fit_problem(inside, controller(1000, 400, 300), "job.gcode"), std::nullopt);
  auto beyond = job("", "G0 X-10 Y-10\nG1 X-390 Y-310 F600 S800\n");
  EXPECT_TRUE(job_fit_problem(beyond, controller(1000, 400, 300), "job.gcode"));
  auto straddling = job("", "G0 X-10 Y10\nG1 X10 Y10 F600 S800\n");
  EXPECT_TRUE(job_fit_problem(straddling, controller(1000, 400, 300), "job.gcode"));
}

TEST(LaserJobChecks, TravelIsNotCheckedWhenTheControllerDoesNotReportIt) {
  auto p = job("", "G1 X900 Y900 F600 S800\n");
  EXPECT_EQ(job_fit_problem(p, controller(1000, 0, 0), "job.gcode"), std::nullopt);
}

TEST(LaserJobChecks, RapidRateIsTheSlowerAxisOrAGuess) {
  grbl::MachineInfo info;
  EXPECT_EQ(rapid_rate(info), 6000);
  info.settings = {{110, 8000}, {111, 5000}};
  EXPECT_EQ(rapid_rate(info), 5000);
}
