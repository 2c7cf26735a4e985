// End to end, one piece at a time: the built atelierd and atelierctl with the knitting-machine
// emulator. Knit jobs wait for `atelierctl start ID`; `--from-row` knits the rest of the
// pattern; bad start options are refused naming the job and the values; a job whose sidecar
// says autostart knits alone. The emulator's record is what the needles did.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <string>
#include <vector>

#include "tests/e2e/daemon_harness.h"

namespace fs = std::filesystem;
using atelier::test::CommandResult;
using atelier::test::DaemonProcess;
using atelier::test::TempDir;

namespace {

CommandResult ctl(const DaemonProcess& daemon, std::vector<std::string> args) {
  args.insert(args.begin(), {atelier::test::binary("atelierctl").string(), "--socket", daemon.socket().string()});
  return atelier::test::run_command(args);
}

struct KnitterRig {
  TempDir tmp;
  atelier::test::KnitEmulator emulator{3};
  std::unique_ptr<DaemonProcess> daemon;

  KnitterRig() {
    // No autostart: what a [[device]] for a knitting machine is by default.
    daemon = std::make_unique<DaemonProcess>(
        tmp.path(), "[knit]\nwidth = 40\n[[device]]\nname = \"knitter\"\ndriver = \"ayab\"\nport = \"" +
                        emulator.link().string() + "\"\nmachine = \"kh930\"\n");
    daemon->start();
  }
  // Drops tests/data/`image` as `name` (with `sidecar` as NAME.toml first, unless empty).
  void drop(const std::string& image, const std::string& name, const std::string& sidecar = "") {
    const fs::path in = daemon->incoming("knit");
    if (!sidecar.empty()) {
      atelier::test::write_file(tmp.path() / (name + ".toml"), sidecar);
      atelier::test::drop_file(tmp.path() / (name + ".toml"), in / (name + ".toml"));
    }
    atelier::test::drop_file(atelier::test::test_image(image), in / name);
  }
  std::string id(const std::string& name) { return std::to_string(daemon->job_named(name)["id"].get<int>()); }
  std::string state(const std::string& name) { return daemon->job_named(name)["state"]; }
  int pattern_rows(const std::string& name) {
    const std::string dir = daemon->job_named(name)["output_dir"];
    return cv::imread(dir + "/pattern.png", cv::IMREAD_GRAYSCALE).rows;
  }
};

TEST(E2EKnitStart, KnitJobsWaitForTheKnitterAndFromRowKnitsTheRestOfThePattern) {
  KnitterRig rig;
  // The same image twice: the same pattern, so the first job's rows from row 5 are the
  // second's, whatever order the rows are knitted in.
  rig.drop("pic3.png", "first.png");
  ASSERT_TRUE(rig.daemon->wait_job_state("first.png", "ready")) << rig.daemon->log();
  rig.drop("pic3.png", "second.png");
  ASSERT_TRUE(rig.daemon->wait_job_state("second.png", "ready")) << rig.daemon->log();
  const std::string first = rig.id("first.png"), second = rig.id("second.png");
  EXPECT_EQ(rig.daemon->job_named("first.png")["reason"],
            "converted; waiting for knitter and `atelierctl start " + first + "`");
  EXPECT_TRUE(rig.emulator.recorded().empty()) << "a job was knitted without `atelierctl start`";

  // Bad options: refused with the job and the values, nothing starts.
  const int rows = rig.pattern_rows("first.png");
  ASSERT_GT(rows, 5);
  CommandResult r = ctl(*rig.daemon, {"start", first, "--from-row", std::to_string(rows + 1)});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("job " + first + ": --from-row " + std::to_string(rows + 1) + " is outside the pattern (rows 1 to "),
            std::string::npos) << r.err;
  r = ctl(*rig.daemon, {"start", first, "--start-needle", "R90"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("job " + first + ": --start-needle R90 puts the pattern's 40 stitches on needles R90 to R129, "
                       "off the kh930's bed (L100 to R100)"),
            std::string::npos) << r.err;
  r = ctl(*rig.daemon, {"start", first, "--start-needle", "left"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--start-needle left is not a needle of the kh930"), std::string::npos) << r.err;
  EXPECT_EQ(rig.state("first.png"), "ready");

  r = ctl(*rig.daemon, {"start", first, "--from-row", "5", "--start-needle", "L40"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The second waits while the first knits, and after it.
  ASSERT_TRUE(rig.daemon->wait_for([&] {
    EXPECT_EQ(rig.state("second.png"), "ready");
    return rig.state("first.png") == "completed";
  })) << rig.daemon->log();
  const auto first_rows = rig.emulator.recorded();
  ASSERT_EQ(first_rows.size(), static_cast<size_t>(rows - 4));
  r = ctl(*rig.daemon, {"show", first});
  EXPECT_NE(r.out.find("knitting on knitter from row 5, needles L40 to L1"), std::string::npos) << r.out;
  EXPECT_EQ(rig.state("second.png"), "ready");

  r = ctl(*rig.daemon, {"start", second});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(rig.daemon->wait_job_state("second.png", "completed")) << rig.daemon->log();
  const auto all = rig.emulator.recorded();
  ASSERT_EQ(all.size(), first_rows.size() + static_cast<size_t>(rows));
  EXPECT_EQ(first_rows, std::vector<std::string>(all.end() - (rows - 4), all.end()))
      << "the first job knitted rows 5 to the end of the pattern";
}

TEST(E2EKnitStart, AJobWhoseSidecarSaysAutostartKnitsAloneFromItsStartRow) {
  KnitterRig rig;
  rig.drop("pic1.png", "waits.png");
  ASSERT_TRUE(rig.daemon->wait_job_state("waits.png", "ready")) << rig.daemon->log();
  rig.drop("pic1.png", "alone.png", "autostart = true\nstart_row = 3\n");
  ASSERT_TRUE(rig.daemon->wait_job_state("alone.png", "completed")) << rig.daemon->log();
  const int rows = rig.pattern_rows("alone.png");
  EXPECT_EQ(rig.emulator.recorded().size(), static_cast<size_t>(rows - 2));
  EXPECT_EQ(rig.state("waits.png"), "ready");
  // A bad sidecar key fails the conversion, naming the file, line and key.
  rig.drop("pic1.png", "bad.png", "width = 30\nstart_needle = \"Q7\"\n");
  ASSERT_TRUE(rig.daemon->wait_job_state("bad.png", "failed")) << rig.daemon->log();
  const std::string reason = rig.daemon->job_named("bad.png")["reason"];
  EXPECT_NE(reason.find("bad.png.toml:2: key 'start_needle': 'Q7' is no needle"), std::string::npos) << reason;
}

}  // namespace
