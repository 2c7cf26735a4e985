// The atelier-convert program as the daemon and users run it: exit codes and what it writes.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const fs::path kData = ATELIER_TEST_DATA;
const fs::path kTool = fs::path(ATELIER_BINARY_DIR) / "bin" / "atelier-convert";

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class ConvertToolTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::exists(kTool)) << kTool << " is not built (ninja atelier-convert)";
    dir_ = fs::temp_directory_path() /
           ("atelier-convert-tool-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Runs the tool with `args` (already quoted), stderr to a file; returns the exit code.
  int tool(const std::string& args) {
    std::string cmd = "'" + kTool.string() + "' " + args + " >/dev/null 2>'" +
                      (dir_ / "stderr.txt").string() + "'";
    int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  std::string err() { return slurp(dir_ / "stderr.txt"); }
  static std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

  fs::path dir_;
};

TEST_F(ConvertToolTest, GoodImageWritesTheJobFolder) {
  fs::path out = dir_ / "out";
  ASSERT_EQ(tool("knit " + q(kData / "pic3.png") + " " + q(out) + " --set width=48"), 0) << err();
  for (const char* name :
       {"pattern.png", "preview.png", "chart.pdf", "pattern.k", "report.json", "pic3.png"})
    EXPECT_TRUE(fs::exists(out / name)) << name;
  EXPECT_EQ(slurp(out / "pic3.png"), slurp(kData / "pic3.png"));
  EXPECT_EQ(cv::imread((out / "pattern.png").string()).cols, 48);
  // A second run over the same folder (read-only source copy included) still works.
  EXPECT_EQ(tool("knit " + q(kData / "pic3.png") + " " + q(out) + " --set width=48"), 0) << err();
}

TEST_F(ConvertToolTest, ParamsThenSidecarThenSet) {
  fs::path input = dir_ / "pic.png";
  fs::copy_file(kData / "pic3.png", input);
  std::ofstream(dir_ / "defaults.toml") << "width = 40\nmax_float = 5\n";
  ASSERT_EQ(tool("knit " + q(input) + " " + q(dir_ / "a") + " --params " + q(dir_ / "defaults.toml")),
            0) << err();
  nlohmann::json a = nlohmann::json::parse(slurp(dir_ / "a" / "report.json"));
  EXPECT_EQ(a["grid"]["stitches"], 40);
  EXPECT_EQ(a["max_float"], 5);

  std::ofstream(dir_ / "pic.png.toml") << "width = 44\n";
  ASSERT_EQ(tool("knit " + q(input) + " " + q(dir_ / "b") + " --params " + q(dir_ / "defaults.toml")),
            0) << err();
  nlohmann::json b = nlohmann::json::parse(slurp(dir_ / "b" / "report.json"));
  EXPECT_EQ(b["grid"]["stitches"], 44);
  EXPECT_EQ(b["max_float"], 5);

  ASSERT_EQ(tool("knit " + q(input) + " " + q(dir_ / "c") + " --params " +
                 q(dir_ / "defaults.toml") + " --set width=52 --set seed=3"),
            0) << err();
  nlohmann::json c = nlohmann::json::parse(slurp(dir_ / "c" / "report.json"));
  EXPECT_EQ(c["grid"]["stitches"], 52);
  EXPECT_EQ(c["parameters"]["seed"], 3);
}

TEST_F(ConvertToolTest, ParamsFromStdinLikeTheDaemon) {
  std::ofstream(dir_ / "d.toml") << "width = 36\n";
  ASSERT_EQ(tool("knit " + q(kData / "pic3.png") + " " + q(dir_ / "out") +
                 " --params /dev/stdin --progress-fd 1 < " + q(dir_ / "d.toml")),
            0) << err();
  EXPECT_EQ(cv::imread((dir_ / "out" / "pattern.png").string()).cols, 36);
}

TEST_F(ConvertToolTest, ProgressLinesGoToTheGivenFd) {
  std::string cmd = "'" + kTool.string() + "' knit " + q(kData / "pic3.png") + " " +
                    q(dir_ / "out") + " --set width=30 --progress-fd 3 3>" +
                    q(dir_ / "progress.txt") + " 2>/dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  std::string text = slurp(dir_ / "progress.txt");
  EXPECT_EQ(text.rfind("progress 0", 0), 0u) << text;
  EXPECT_THAT(text, HasSubstr("progress 1.00\n"));
}

TEST_F(ConvertToolTest, BadImageExitsOneNamingTheFile) {
  std::ofstream(dir_ / "pic.png") << "not a picture\n";
  EXPECT_EQ(tool("knit " + q(dir_ / "pic.png") + " " + q(dir_ / "out")), 1);
  EXPECT_THAT(err(), HasSubstr("pic.png: not an image"));
  EXPECT_EQ(tool("knit " + q(dir_ / "nothing.png") + " " + q(dir_ / "out")), 1);
  EXPECT_THAT(err(), HasSubstr("nothing.png"));
  EXPECT_EQ(tool("knit " + q(kData / "pic3.png") + " " + q(dir_ / "out") + " --max-pixels 1000"), 1);
  EXPECT_THAT(err(), HasSubstr("pic3.png"));
}

TEST_F(ConvertToolTest, BadParametersExitOneNamingFileAndLine) {
  std::ofstream(dir_ / "p.toml") << "width = 40\nwidht = 41\n";
  EXPECT_EQ(tool("knit " + q(kData / "pic3.png") + " " + q(dir_ / "out") + " --params " +
                 q(dir_ / "p.toml")),
            1);
  EXPECT_THAT(err(), HasSubstr("p.toml:2"));
  EXPECT_THAT(err(), HasSubstr("widht"));
  EXPECT_EQ(tool("knit " + q(kData / "pic3.png") + " " + q(dir_ / "out") + " --set max_float=99"), 1);
  EXPECT_THAT(err(), HasSubstr("max_float"));
  EXPECT_EQ(tool("knit " + q(kData / "pic3.png") + " " + q(dir_ / "out") + " --set novalue"), 1);
}

TEST_F(ConvertToolTest, UsageErrorsExitTwo) {
  EXPECT_EQ(tool(""), 2);
  EXPECT_EQ(tool("knit " + q(kData / "pic3.png")), 2);
  EXPECT_EQ(tool("knit " + q(kData / "pic3.png") + " " + q(dir_ / "out") + " --bogus"), 2);
  EXPECT_EQ(tool("crochet " + q(kData / "pic3.png") + " " + q(dir_ / "out")), 2);
  EXPECT_THAT(err(), HasSubstr("knit"));
  EXPECT_FALSE(fs::exists(dir_ / "out"));
  // A known kind given the wrong sort of input is bad input (1), named.
  EXPECT_EQ(tool("lace " + q(kData / "pic3.png") + " " + q(dir_ / "out")), 1);
  EXPECT_THAT(err(), HasSubstr("pic3.png: a lace job is a TOML job file"));
  EXPECT_EQ(tool("knit - " + q(dir_ / "out")), 1);
  EXPECT_THAT(err(), HasSubstr("needs an input file"));
  EXPECT_EQ(tool("--help"), 0);
}

TEST_F(ConvertToolTest, RunningOutOfTheMemoryBudgetNamesTheInputAndTheLimit) {
  // 36 Mpx decode to 108 MB, with more for the stitch grid: more than a 256 MB budget holds
  // (it converts with 600). The reason names the file and the budget, not std::bad_alloc.
  const fs::path big = dir_ / "big.png";
  ASSERT_TRUE(cv::imwrite(big.string(), cv::Mat(6000, 6000, CV_8UC3, cv::Scalar(128, 128, 128))));
  EXPECT_EQ(tool("knit " + q(big) + " " + q(dir_ / "out") + " --set width=100 --memory-mb 256"), 1);
  EXPECT_EQ(err(), "error: big.png: needs more than 256 MB (limits.job_memory_mb)\n");
}

}  // namespace
