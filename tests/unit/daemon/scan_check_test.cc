// Scans handed to `wood add` are decoded in an `atelier-convert --decode-check` child first
// (daemon/scan_check.h): a file that does not decode, or that crashes or hangs the decoder,
// refuses the request naming the file, and the daemon's own process never decodes it.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "base/error.h"
#include "daemon/scan_check.h"
#include "tests/e2e/daemon_harness.h"
#include "tests/support/fake_program.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

std::string refusal(const fs::path& exe, const std::vector<fs::path>& files, ChildLimits limits = {}) {
  try {
    check_scans_decode(exe, files, limits);
  } catch (const BadInput& e) {
    return e.what();
  }
  return "";
}

TEST(ScanCheck, AScanThatDecodesPassesAndOneThatDoesNotIsRefusedByName) {
  test::TempDir tmp;
  cv::imwrite((tmp.path() / "oak.png").string(), cv::Mat(40, 60, CV_8UC3, cv::Scalar(40, 90, 160)));
  cv::imwrite((tmp.path() / "oak.mask.png").string(), cv::Mat(40, 60, CV_8UC1, cv::Scalar(255)));
  EXPECT_EQ(refusal(test::binary("atelier-convert"), {tmp.path() / "oak.png", tmp.path() / "oak.mask.png"}), "");

  // A PNG cut short after its header: the header passes the limits, the data does not decode.
  const std::string png = test::read_file(tmp.path() / "oak.png");
  test::write_file(tmp.path() / "walnut.png", png.substr(0, 60) + "SECRET-TEXT-1234");
  const std::string reason = refusal(test::binary("atelier-convert"), {tmp.path() / "oak.png", tmp.path() / "walnut.png"});
  EXPECT_NE(reason.find("walnut.png"), std::string::npos) << reason;
  EXPECT_EQ(reason.find("SECRET-TEXT"), std::string::npos) << reason;
}

TEST(ScanCheck, ADecoderThatCrashesOrHangsCostsTheRequestOnly) {
  test::TempDir tmp;
  test::write_file(tmp.path() / "scan.png", "x");
  const std::string crashed = refusal(test::fake_program(tmp, "kill -SEGV $$"), {tmp.path() / "scan.png"});
  EXPECT_NE(crashed.find("scan.png"), std::string::npos) << crashed;
  EXPECT_NE(crashed.find("signal 11"), std::string::npos) << crashed;

  ChildLimits quick;
  quick.timeout = 300ms;
  const std::string hung = refusal(test::fake_program(tmp, "exec sleep 30"), {tmp.path() / "scan.png"}, quick);
  EXPECT_NE(hung.find("scan.png"), std::string::npos) << hung;
  EXPECT_NE(hung.find("longer than"), std::string::npos) << hung;
}

TEST(ChildProcess, ReportsExitCodesSignalsAndOutputOfTheChild) {
  test::TempDir tmp;
  const ChildResult said = run_child({test::fake_program(tmp, "echo lace; echo 'error: bad' >&2; exit 3").string()}, {});
  EXPECT_EQ(said.end, ChildResult::End::exited);
  EXPECT_EQ(said.code, 3);
  EXPECT_EQ(first_line(said.out), "lace");
  EXPECT_EQ(first_line(said.err), "error: bad");

  ChildLimits one_second_of_cpu;
  one_second_of_cpu.cpu_seconds = 1;
  const ChildResult spun = run_child({test::fake_program(tmp, "while :; do :; done").string()}, one_second_of_cpu);
  EXPECT_TRUE(spun.out_of_cpu());
}

}  // namespace
}  // namespace atelier
