// Strict reading of knit parameters: what a user's sidecar typo must produce.
#include "convert/knit/knit_params.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "convert/convert.h"
#include "convert/kinds.h"
#include "convert/common/param_table.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

toml::table parse(const std::string& text) { return toml::parse(text, std::string_view{"job.toml"}); }

std::string param_error(const std::string& text) {
  try {
    read_knit_params(parse(text), "job.toml");
  } catch (const ParamError& e) {
    return e.what();
  }
  return "";
}

TEST(ConvertKnitParams, DefaultsMatchTheDesign) {
  KnitParams p = read_knit_params(toml::table{}, "empty");
  EXPECT_EQ(p.width, 120);
  EXPECT_EQ(p.max_float, 4);
  EXPECT_EQ(p.dither, "auto");
  EXPECT_EQ(p.solver, "auto");  // issue 22: chosen by measurement with the dither
  EXPECT_TRUE(p.anchoring);
  EXPECT_FALSE(p.invert);
  EXPECT_EQ(p.threshold, 128);
  EXPECT_EQ(p.rgb[0].r, 0xf4);
  EXPECT_EQ(p.rgb[1].b, 0x5c);
  EXPECT_EQ(p.first_row, "bottom");  // as AYAB desktop: the fabric is the picture upright
}

TEST(ConvertKnitParams, ReadsEveryKey) {
  KnitParams p = read_knit_params(parse(R"(
width = 64
stitches_per_10cm = 30.5
rows_per_10cm = 40
orientation = "vertical"
dither = "atkinson"
threshold = 100
max_float = 6
anchoring = false
relax_mask = "mask.png"
solver = "gsat"
seed = 7
rw_n = 50
rw_q = 3
rw_m = 2
invert = true
colors = ["#ffffff", "#000000"]
first_row = "top"
)"),
                                  "job.toml");
  EXPECT_EQ(p.width, 64);
  EXPECT_DOUBLE_EQ(p.stitches_per_10cm, 30.5);
  EXPECT_EQ(p.gauge().orientation, knit::Orientation::vertical);
  EXPECT_EQ(p.dither_method(), knit::Dither::atkinson);
  EXPECT_EQ(p.solver_kind(), knit::Solver::gsat);
  EXPECT_EQ(p.max_float, 6);
  EXPECT_FALSE(p.anchoring);
  EXPECT_EQ(p.seed, 7u);
  EXPECT_TRUE(p.invert);
  EXPECT_EQ(p.rgb[0].g, 255);
  EXPECT_EQ(p.rgb[1].g, 0);
  EXPECT_EQ(p.first_row, "top");
}

TEST(ConvertKnitParams, UnknownKeyNamesFileLineAndKey) {
  EXPECT_THAT(param_error("width = 100\nmax_flaot = 3\n"),
              AllOf(HasSubstr("job.toml:2"), HasSubstr("max_flaot"), HasSubstr("unknown")));
}

TEST(ConvertKnitParams, WrongTypeNamesFileLineAndKey) {
  EXPECT_THAT(param_error("\nwidth = \"wide\"\n"),
              AllOf(HasSubstr("job.toml:2"), HasSubstr("width"), HasSubstr("integer")));
  EXPECT_THAT(param_error("anchoring = 1\n"),
              AllOf(HasSubstr("job.toml:1"), HasSubstr("anchoring")));
}

TEST(ConvertKnitParams, OutOfRangeAndBadChoicesAreRefused) {
  EXPECT_THAT(param_error("\n\nmax_float = 1\n"),
              AllOf(HasSubstr("job.toml:3"), HasSubstr("max_float"), HasSubstr("outside")));
  EXPECT_THAT(param_error("width = 5000\n"), AllOf(HasSubstr("job.toml:1"), HasSubstr("width")));
  EXPECT_THAT(param_error("dither = \"jarvis\"\n"),
              AllOf(HasSubstr("job.toml:1"), HasSubstr("dither"), HasSubstr("floyd-steinberg")));
  EXPECT_THAT(param_error("colors = [\"#fff\", \"#000000\"]\n"),
              AllOf(HasSubstr("job.toml:1"), HasSubstr("colors"), HasSubstr("#rrggbb")));
  EXPECT_THAT(param_error("colors = [\"#ffffff\"]\n"), HasSubstr("two colours"));
  EXPECT_THAT(param_error("first_row = \"left\"\n"),
              AllOf(HasSubstr("job.toml:1"), HasSubstr("first_row"), HasSubstr("bottom"), HasSubstr("top")));
}

TEST(ConvertKnitParams, ValidateKindParamsUsesTheKnitReader) {
  EXPECT_NO_THROW(validate_kind_params("knit", parse("width = 80\n"), "job.toml"));
  EXPECT_THROW(validate_kind_params("knit", parse("colour = 3\n"), "job.toml"), ParamError);
  EXPECT_THROW(validate_kind_params("quilt", toml::table{}, "job.toml"), ParamError);
  EXPECT_TRUE(is_known_kind("knit"));
  EXPECT_TRUE(is_known_kind("lace"));
  EXPECT_FALSE(is_known_kind("quilt"));
}

TEST(ConvertKnitParams, RelaxMaskResolvesBesideTheInput) {
  fs::path dir = fs::temp_directory_path() / ("atelier-relax-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  fs::path input = dir / "cat.jpg";
  KnitParams p;
  EXPECT_TRUE(resolve_relax_mask(p, input).empty());
  std::ofstream(dir / "cat.jpg.relax.png") << "x";
  EXPECT_EQ(resolve_relax_mask(p, input), dir / "cat.jpg.relax.png");
  p.relax_mask = "masks/m.png";
  EXPECT_EQ(resolve_relax_mask(p, input), dir / "masks/m.png");
  p.relax_mask = "/abs/m.png";
  EXPECT_EQ(resolve_relax_mask(p, input), fs::path("/abs/m.png"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace atelier
