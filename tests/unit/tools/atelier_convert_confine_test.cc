// atelier-convert --confine (as atelierd runs it): every path-valued parameter that a job sets
// stays inside the spool and never goes through a symlink; paths from --params do not.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "convert/sketch/pencil_profile_file.h"
#include "tests/support/convert_tool.h"

namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

const fs::path kData = ATELIER_TEST_DATA;

// One path-valued parameter: its kind, key, how the job sets it and what it names.
struct PathParam {
  std::string name;       // test label
  std::string kind;
  std::string key;
  std::string target;     // file or folder name the value points to
  // The job's layer (sidecar, or the job file for lace) with the value.
  std::function<std::string(const std::string& value)> layer;
  // Makes a valid target at `at`.
  std::function<void(const fs::path& at)> make;
};

void small_image(const fs::path& from, const fs::path& to, int side) {
  cv::Mat m = cv::imread(from.string());
  cv::resize(m, m, cv::Size(side, side));
  fs::create_directories(to.parent_path());
  cv::imwrite(to.string(), m);
}

std::string toml_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) out += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
  return out + "\"";
}

const std::vector<PathParam>& params() {
  static const std::vector<PathParam> list = {
      {"knit_relax_mask", "knit", "relax_mask", "mask.png",
       [](const std::string& v) { return "width = 24\nrelax_mask = " + toml_string(v) + "\n"; },
       [](const fs::path& at) { small_image(kData / "pic1.png", at, 40); }},
      {"lace_start_chart", "lace", "start_chart", "start.txt",
       [](const std::string& v) {
         return "kind = \"lace\"\ngenerations = 0\npopulation = 4\nstart_chart = " + toml_string(v) + "\n";
       },
       [](const fs::path& at) { atelier::test::ConvertToolFixture::write(at, "Row 1 (RS): k2, yo, k2tog.\n"); }},
      {"sketch_pencil", "sketch", "pencil", "mine.toml",
       [](const std::string& v) { return "pencil = " + toml_string(v) + "\nmax_lines = 20\n"; },
       [](const fs::path& at) {
         atelier::test::ConvertToolFixture::write(at, atelier::profile_to_toml(atelier::shipped_pencil("HB")));
       }},
      {"embroidery_textures", "embroidery", "textures", "tex",
       [](const std::string& v) { return "textures = " + toml_string(v) + "\n"; },
       [](const fs::path& at) { fs::create_directories(at); }},
      {"parquetry_wood_folder", "parquetry", "wood", "wood",
       [](const std::string& v) {
         return "wood = " + toml_string(v) + "\ndpi = 25.4\nsize_mm = 42\npatch_mm = 14\nrotations = 2\n";
       },
       [](const fs::path& at) {
         fs::create_directories(at);
         fs::copy_file(kData / "wood" / "brazilwood_dark.png", at / "brazilwood_dark.png");
       }},
      {"parquetry_wood_sheet_image", "parquetry", "wood", "sheet.png",
       [](const std::string& v) {
         return "wood = [{id = \"b\", image = " + toml_string(v) +
                "}]\ndpi = 25.4\nsize_mm = 42\npatch_mm = 14\nrotations = 2\n";
       },
       [](const fs::path& at) {
         fs::create_directories(at.parent_path());
         fs::copy_file(kData / "wood" / "brazilwood_dark.png", at);
       }},
  };
  return list;
}

class ConfineTest : public atelier::test::ConvertToolFixture,
                    public ::testing::WithParamInterface<PathParam> {
 protected:
  fs::path spool() const { return dir_ / "spool"; }
  // The job's folder in the spool, where its layer lives.
  fs::path job_dir() const {
    const PathParam& p = GetParam();
    return p.kind == "lace" ? spool() / "incoming" : spool() / "incoming" / p.kind;
  }
  fs::path layer_file() const {
    return GetParam().kind == "lace" ? job_dir() / "swatch.toml" : job_dir() / "pic.png.toml";
  }
  // Runs the job with the parameter set to `value`; returns the exit code.
  int run(const std::string& value) {
    const PathParam& p = GetParam();
    write(layer_file(), p.layer(value));
    fs::path input = layer_file();
    if (p.kind != "lace") {
      input = job_dir() / "pic.png";
      if (!fs::exists(input)) small_image(kData / "pic3.png", input, 48);
    }
    fs::remove_all(dir_ / "out");
    return tool(p.kind + " " + q(input) + " " + q(dir_ / "out") + " --confine " + q(spool()));
  }
  void expect_refused(const std::string& value, const std::string& why) {
    EXPECT_EQ(run(value), 1) << value;
    const std::string e = err();
    EXPECT_THAT(e, HasSubstr(layer_file().filename().string())) << e;
    EXPECT_THAT(e, HasSubstr("key '" + GetParam().key + "'")) << e;
    EXPECT_THAT(e, HasSubstr(why)) << e;
    EXPECT_LE(e.size(), 300u) << e;
  }
};

TEST_P(ConfineTest, AnAbsolutePathOutsideTheSpoolIsRefused) {
  const fs::path outside = dir_ / "private" / GetParam().target;
  GetParam().make(outside);
  expect_refused(outside.string(), "outside the spool");
}

TEST_P(ConfineTest, ADotDotEscapeIsRefused) {
  const fs::path outside = dir_ / "private" / GetParam().target;
  GetParam().make(outside);
  expect_refused(outside.lexically_relative(job_dir()).string(), "outside the spool");
}

TEST_P(ConfineTest, ASymlinkInsideTheSpoolPointingOutIsRefused) {
  const fs::path outside = dir_ / "private" / GetParam().target;
  GetParam().make(outside);
  fs::create_directories(job_dir());
  fs::create_symlink(outside, job_dir() / ("link-" + GetParam().target));
  expect_refused("link-" + GetParam().target, "symbolic link");
}

TEST_P(ConfineTest, AFileInsideTheSpoolIsAccepted) {
  GetParam().make(job_dir() / GetParam().target);
  EXPECT_EQ(run(GetParam().target), 0) << err();
  EXPECT_TRUE(fs::exists(dir_ / "out" / "report.json"));
}

INSTANTIATE_TEST_SUITE_P(EachPathParameter, ConfineTest, ::testing::ValuesIn(params()),
                         [](const auto& info) { return info.param.name; });

class ConfineToolTest : public atelier::test::ConvertToolFixture {};

TEST_F(ConfineToolTest, AJobMayNotChooseTheStockFolderAndNoneIsCreated) {
  const fs::path spool = dir_ / "spool", in = spool / "incoming" / "parquetry";
  small_image(kData / "pic3.png", in / "pic.png", 48);
  write(dir_ / "defaults.toml", "wood = " + toml_string((kData / "wood").string()) +
                                    "\ndpi = 25.4\nsize_mm = 42\npatch_mm = 14\nrotations = 2\n");
  write(in / "pic.png.toml", "stock = " + toml_string((dir_ / "elsewhere").string()) + "\n");
  EXPECT_EQ(tool("parquetry " + q(in / "pic.png") + " " + q(dir_ / "out") + " --params " +
                 q(dir_ / "defaults.toml") + " --confine " + q(spool)),
            1);
  EXPECT_THAT(err(), HasSubstr("pic.png.toml: key 'stock': a job may not choose the stock folder"));
  EXPECT_FALSE(fs::exists(dir_ / "elsewhere"));
  // From the daemon's config the stock is the workshop's, but the converter creates none.
  fs::remove(in / "pic.png.toml");
  write(dir_ / "defaults.toml", slurp(dir_ / "defaults.toml") + "stock = " +
                                    toml_string((dir_ / "stock").string()) + "\n");
  EXPECT_EQ(tool("parquetry " + q(in / "pic.png") + " " + q(dir_ / "out") + " --params " +
                 q(dir_ / "defaults.toml") + " --confine " + q(spool)),
            1);
  EXPECT_THAT(err(), HasSubstr("stock: no such stock folder"));
  EXPECT_FALSE(fs::exists(dir_ / "stock"));
  fs::create_directories(dir_ / "stock");
  EXPECT_EQ(tool("parquetry " + q(in / "pic.png") + " " + q(dir_ / "out") + " --params " +
                 q(dir_ / "defaults.toml") + " --confine " + q(spool)),
            0) << err();
  EXPECT_TRUE(fs::exists(dir_ / "stock" / "stock.json"));
}

TEST_F(ConfineToolTest, PathsFromTheConfigAndFromSetFollowTheirOrigin) {
  const fs::path spool = dir_ / "spool", in = spool / "incoming" / "knit";
  small_image(kData / "pic3.png", in / "pic.png", 48);
  small_image(kData / "pic1.png", dir_ / "shared" / "mask.png", 40);
  // The daemon's config may name any file.
  write(dir_ / "defaults.toml", "width = 24\nrelax_mask = " + toml_string((dir_ / "shared" / "mask.png").string()) + "\n");
  EXPECT_EQ(tool("knit " + q(in / "pic.png") + " " + q(dir_ / "out") + " --params " + q(dir_ / "defaults.toml") +
                 " --confine " + q(spool)),
            0) << err();
  // --set is the job's: refused, and so is a FIFO (it would block) inside the spool.
  EXPECT_EQ(tool("knit " + q(in / "pic.png") + " " + q(dir_ / "out") + " --confine " + q(spool) +
                 " --set relax_mask=" + q(dir_ / "shared" / "mask.png")),
            1);
  EXPECT_THAT(err(), HasSubstr("--set: key 'relax_mask': "));
  EXPECT_THAT(err(), HasSubstr("mask.png: outside the spool"));
  // A second allowed folder (what [spool] allow_paths passes) lets it through.
  EXPECT_EQ(tool("knit " + q(in / "pic.png") + " " + q(dir_ / "out") + " --confine " + q(spool) + " --confine " +
                 q(dir_ / "shared") + " --set width=24 --set relax_mask=" + q(dir_ / "shared" / "mask.png")),
            0) << err();
}

}  // namespace
