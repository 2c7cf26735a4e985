// read_laser_params: the [laser] table, strictly, with LightBurn-like default layers.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "convert/common/laser_params.h"
#include "convert/common/param_table.h"

namespace atelier {
namespace {

using ::testing::HasSubstr;

LaserParams parse(const std::string& text) {
  toml::table t = toml::parse(text, std::string_view{"atelierd.toml"});
  const toml::table* laser = t.get_as<toml::table>("laser");
  // Not `laser ? *laser : toml::table{}`: that copies, and copies lose their line numbers.
  if (laser) return read_laser_params(*laser, "atelierd.toml");
  return read_laser_params(toml::table{}, "atelierd.toml");
}

std::string error_of(const std::string& text) {
  try {
    parse(text);
  } catch (const ParamError& e) {
    return e.what();
  }
  return "";
}

TEST(LaserParams, DefaultsAreLightBurnLike) {
  LaserParams p = parse("");
  EXPECT_DOUBLE_EQ(p.machine.width_mm, 400);
  EXPECT_DOUBLE_EQ(p.machine.s_max, 1000);
  EXPECT_DOUBLE_EQ(p.machine.accel_mm_s2, 500);
  EXPECT_DOUBLE_EQ(p.machine.junction_deviation_mm, 0.010);
  EXPECT_FALSE(p.check_first);
  ASSERT_EQ(p.layers.size(), 3u);
  EXPECT_EQ(p.layers[0].color, "#000000");
  EXPECT_EQ(p.layers[0].mode, laser::Mode::cut);
  EXPECT_DOUBLE_EQ(p.layers[0].speed_mm_min, 600);
  EXPECT_DOUBLE_EQ(p.layers[0].power_pct, 80);
  EXPECT_EQ(p.layers[1].color, "#ff0000");
  EXPECT_EQ(p.layers[2].color, "#0000ff");
  EXPECT_EQ(p.layers[2].mode, laser::Mode::engrave);
  EXPECT_DOUBLE_EQ(p.layers[2].speed_mm_min, 3000);
  EXPECT_DOUBLE_EQ(p.layers[2].power_pct, 20);
}

TEST(LaserParams, ReadsEveryKey) {
  LaserParams p = parse(R"([laser]
work_area_mm = [300, 200.5]
s_max = 255
travel_mm_min = 3000
acceleration_mm_s2 = 800
junction_deviation_mm = 0.02
tolerance_mm = 0.02
check_first = true
start_from = "here"
[[laser.layer]]
color = "#F0A"
name = "pink engrave"
mode = "engrave"
speed_mm_min = 2000
power_pct = 35.5
passes = 2
[[laser.layer]]
color = "green"
kerf_mm = 0.15
)");
  EXPECT_DOUBLE_EQ(p.machine.width_mm, 300);
  EXPECT_DOUBLE_EQ(p.machine.height_mm, 200.5);
  EXPECT_DOUBLE_EQ(p.machine.s_max, 255);
  EXPECT_DOUBLE_EQ(p.machine.accel_mm_s2, 800);
  EXPECT_DOUBLE_EQ(p.machine.junction_deviation_mm, 0.02);
  EXPECT_DOUBLE_EQ(p.machine.travel_mm_min, 3000);
  EXPECT_DOUBLE_EQ(p.tolerance_mm, 0.02);
  EXPECT_TRUE(p.check_first);
  EXPECT_EQ(p.start_from, "here");
  ASSERT_EQ(p.layers.size(), 2u) << "configured layers replace the defaults";
  EXPECT_EQ(p.layers[0].color, "#ff00aa");
  EXPECT_EQ(p.layers[0].name, "pink engrave");
  EXPECT_EQ(p.layers[0].mode, laser::Mode::engrave);
  EXPECT_EQ(p.layers[0].passes, 2);
  EXPECT_DOUBLE_EQ(p.layers[0].power_pct, 35.5);
  EXPECT_EQ(p.layers[1].color, "#008000") << "SVG's green";
  EXPECT_EQ(p.layers[1].name, "green");
  EXPECT_EQ(p.layers[1].mode, laser::Mode::cut);
  EXPECT_DOUBLE_EQ(p.layers[1].kerf_mm, 0.15);
  EXPECT_EQ(layer_for_color(p, "#008000"), &p.layers[1]);
  EXPECT_EQ(layer_for_color(p, "#000000"), nullptr);
}

TEST(LaserParams, ErrorsNameFileLineAndKey) {
  // Contract A: the driver places jobs now; the old key is refused, saying how.
  EXPECT_THAT(error_of("[laser]\norigin = \"rear-right\"\n"),
              HasSubstr("atelierd.toml:2: key 'laser.origin': is no longer read"));
  EXPECT_THAT(error_of("[laser]\norigin = \"front-left\"\n"),
              HasSubstr("start_from = \"bed\" | \"origin\" | \"here\""));
  EXPECT_THAT(error_of("[laser]\nstart_from = \"home\"\n"),
              HasSubstr("atelierd.toml:2: key 'laser.start_from'"));
  EXPECT_THAT(error_of("[laser]\nacceleration_mm_s2 = 0\n"),
              HasSubstr("atelierd.toml:2: key 'laser.acceleration_mm_s2'"));
  EXPECT_THAT(error_of("[laser]\nwork_area_mm = [400]\n"),
              HasSubstr("atelierd.toml:2: key 'laser.work_area_mm'"));
  EXPECT_THAT(error_of("[laser]\nspeed = 3\n"), HasSubstr("unknown key 'laser.speed'"));
  EXPECT_THAT(error_of("[laser]\n[[laser.layer]]\nname = \"x\"\n"),
              HasSubstr("key 'laser.layer.color': missing"));
  EXPECT_THAT(error_of("[laser]\n[[laser.layer]]\ncolor = \"#12345\"\n"),
              HasSubstr("atelierd.toml:3: key 'laser.layer.color': '#12345' is not a colour"));
  EXPECT_THAT(error_of("[laser]\n[[laser.layer]]\ncolor = \"red\"\npower_pct = 120\n"),
              HasSubstr("atelierd.toml:4: key 'laser.layer.power_pct': value 120 is outside"));
  EXPECT_THAT(error_of("[laser]\n[[laser.layer]]\ncolor = \"red\"\npasses = 0\n"),
              HasSubstr("key 'laser.layer.passes'"));
  EXPECT_THAT(error_of("[laser]\n[[laser.layer]]\ncolor = \"red\"\nmode = \"mark\"\n"),
              HasSubstr("key 'laser.layer.mode'"));
  EXPECT_THAT(error_of("[laser]\n[[laser.layer]]\ncolor = \"red\"\nkerf_mm = 3\n"),
              HasSubstr("key 'laser.layer.kerf_mm'"));
  EXPECT_THAT(error_of("[laser]\n[[laser.layer]]\ncolor = \"red\"\n"
                       "[[laser.layer]]\ncolor = \"#FF0000\"\n"),
              HasSubstr("atelierd.toml:5: key 'laser.layer.color': #ff0000 is already the "
                        "colour of layer 'red'"));
  EXPECT_THAT(error_of("[laser]\ncheck_first = 1\n"), HasSubstr("key 'laser.check_first'"));
}

TEST(LaserParams, ColourNames) {
  EXPECT_EQ(parse_laser_color("#ABCDEF"), "#abcdef");
  EXPECT_EQ(parse_laser_color("#abc"), "#aabbcc");
  EXPECT_EQ(parse_laser_color("Black"), "#000000");
  EXPECT_EQ(parse_laser_color("lime"), "#00ff00");
  EXPECT_FALSE(parse_laser_color("#ggg000").has_value());
  EXPECT_FALSE(parse_laser_color("chartreuse").has_value());
  EXPECT_FALSE(parse_laser_color("").has_value());
}

}  // namespace
}  // namespace atelier
