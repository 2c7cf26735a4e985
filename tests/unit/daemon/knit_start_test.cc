// One piece at a time: a knit job waits for `atelierctl start` (Device::start) unless the
// device or the job's sidecar says autostart, and the start sets the row it begins at and the
// needle of its leftmost stitch (options over the sidecar's start_row / start_needle). Against
// the firmware model (a simulated knitter) in simulated time; the record says which needles
// each row selected and where on the bed it was.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <thread>
#include <vector>

#include "algorithms/lace/chart.h"
#include "convert/lace/lace_chart_json.h"
#include "daemon/job_service.h"
#include "daemon/knit_device.h"
#include "drivers/ayab/knit_plan.h"
#include "drivers/ayab/lace_plan.h"
#include "tests/e2e/daemon_harness.h"
#include "tests/support/job_watch.h"
#include "tests/support/knitter_config.h"
#include "tests/support/lace_test_charts.h"
#include "tests/support/simulated_knitter.h"

namespace atelier {
namespace {

using ::testing::HasSubstr;

// 20 stitches wide, one contrast stitch per row at a different place, so rows differ.
cv::Mat pattern_image(int rows) {
  cv::Mat pattern(rows, 20, CV_8UC1, cv::Scalar(255));
  for (int r = 0; r < rows; ++r) pattern.at<uint8_t>(r, (r * 3) % 20) = 0;
  return pattern;
}

struct StartRig {
  test::TempDir tmp;
  SpoolLayout layout{tmp.path() / "spool"};
  Store store{tmp.path() / "jobs.sqlite"};
  FakeClock clock;
  test::JobWatch watch{clock};
  JobService jobs{store, layout, watch.listener()};
  test::SimulatedKnitter machine{clock, 2};
  // autostart as a [[device]] without the key: no
  DeviceConfig config = test::knitter_device_config(/*autostart=*/false);
  std::unique_ptr<KnitDevice> device;

  StartRig() { jobs.ensure_layout(); }
  ~StartRig() {
    if (device) device->stop();
  }

  // A ready knit job of `rows` rows; `sidecar` is its NAME.png.toml ("" for none).
  int64_t add_job(const std::string& name, int rows, const std::string& sidecar = "") {
    Job job;
    job.id = store.reserve_id();
    job.kind = "knit";
    job.name = name;
    job.state = JobState::ready;
    job.output_dir = (tmp.path() / "done" / std::to_string(job.id)).string();
    std::filesystem::create_directories(job.output_dir);
    cv::imwrite(job.output_dir + "/pattern.png", pattern_image(rows));
    if (!sidecar.empty()) std::ofstream(job.output_dir + "/" + name + ".toml") << sidecar;
    store.insert_job(job);
    return job.id;
  }
  // A ready lace job: chart.json in its output folder, and its job file NAME.toml there (the
  // job file is the lace job's sidecar: `own_keys` are its start keys).
  int64_t add_lace_job(const lace::Chart& chart, int cast_on, int wide, int high, const std::string& own_keys = "") {
    Job job;
    job.id = store.reserve_id();
    job.kind = "lace";
    job.name = "lace.toml";
    job.state = JobState::ready;
    job.output_dir = (tmp.path() / "done" / std::to_string(job.id)).string();
    std::filesystem::create_directories(job.output_dir);
    std::ofstream(job.output_dir + "/chart.json") << lace_chart_to_json({chart, cast_on, wide, high}).dump();
    std::ofstream(job.output_dir + "/lace.toml") << "kind = \"lace\"\n" << own_keys;
    store.insert_job(job);
    return job.id;
  }
  KnitDevice& run() {
    device = std::make_unique<KnitDevice>(
        config, jobs, [this](const std::string&) { return machine.open(); },
        [port = config.port]() -> std::optional<std::string> { return port; }, ayab::SessionTimeouts{}, clock);
    device->start_worker();
    device->wake();
    // A start needs the machine online: the worker's first look at the port says so.
    while (device->describe()["state"] == "offline") std::this_thread::yield();
    return *device;
  }
  // The job's passes as the machine should knit them, placed with its leftmost stitch on
  // needle `start` (0-based), from row `from_row` (1-based) on.
  std::vector<std::string> expected(int rows, int start, int from_row = 1) const {
    cv::Mat p = pattern_image(rows) < 128;
    p /= 255;
    ayab::PlanParams params;
    params.start_needle = start;
    const ayab::KnitPlan plan = ayab::plan_knitting(p, params);
    std::vector<std::string> out;
    for (size_t i = static_cast<size_t>(from_row - 1); i < plan.passes.size(); ++i) {
      std::string line;
      for (int n = plan.start_needle; n <= plan.stop_needle; ++n)
        line.push_back(ayab::needle_selected(plan.passes[i], n) ? '1' : '0');
      out.push_back(line);
    }
    return out;
  }
  JobState state(int64_t id) { return store.get(id)->state; }
};

constexpr int kCentre = (200 - 20) / 2;  // a 20-stitch pattern centred on the KH-930's 200 needles

TEST(KnitStart, KnitJobsWaitForTheKnitterAndTheSecondWaitsWhileTheFirstKnits) {
  StartRig rig;
  const int64_t first = rig.add_job("first.png", 5);
  const int64_t second = rig.add_job("second.png", 4);
  // The one with autostart in its sidecar knits alone, and shows the worker looked: the two
  // without it were passed over.
  const int64_t alone = rig.add_job("alone.png", 3, "autostart = true\n");
  KnitDevice& device = rig.run();
  EXPECT_FALSE(device.autostarts(*rig.store.get(first)));
  EXPECT_TRUE(device.autostarts(*rig.store.get(alone)));
  ASSERT_TRUE(rig.watch.wait_left(alone, JobState::running));
  EXPECT_EQ(rig.state(alone), JobState::completed) << rig.store.get(alone)->reason;
  EXPECT_EQ(rig.state(first), JobState::ready);
  EXPECT_EQ(rig.state(second), JobState::ready);
  EXPECT_EQ(rig.machine.recorded(), rig.expected(3, kCentre)) << "only the autostart job was knitted";

  // The knitter starts the first; the second still waits while it knits, and after it.
  std::vector<JobState> second_while_first_knits;
  rig.machine.on_row = [&] { second_while_first_knits.push_back(rig.state(second)); };
  device.start(first);
  ASSERT_TRUE(rig.watch.wait_left(first, JobState::running));
  rig.machine.on_row = nullptr;
  EXPECT_EQ(rig.state(first), JobState::completed) << rig.store.get(first)->reason;
  ASSERT_FALSE(second_while_first_knits.empty());
  for (JobState s : second_while_first_knits) EXPECT_EQ(s, JobState::ready);
  EXPECT_EQ(rig.state(second), JobState::ready) << "knitted back to back without `atelierctl start`";
  EXPECT_EQ(rig.machine.recorded().size(), 3u + 5u);

  device.start(second);
  ASSERT_TRUE(rig.watch.wait_left(second, JobState::running));
  EXPECT_EQ(rig.state(second), JobState::completed) << rig.store.get(second)->reason;
  EXPECT_EQ(rig.machine.recorded().size(), 3u + 5u + 4u);
}

TEST(KnitStart, FromRowAndStartNeedleKnitTheRestOfThePatternWhereTheKnitterSaid) {
  StartRig rig;
  const int64_t id = rig.add_job("cat.png", 8);
  KnitDevice& device = rig.run();
  StartOptions options;
  options.from_row = 5;
  options.start_needle = "L30";  // the bed's marking: 30 needles left of the centre
  device.start(id, options);
  ASSERT_TRUE(rig.watch.wait_left(id, JobState::running));
  const Job job = *rig.store.get(id);
  ASSERT_EQ(job.state, JobState::completed) << job.reason;
  EXPECT_EQ(rig.machine.recorded(), rig.expected(8, 70, 5)) << "rows 5 to 8, nothing before";
  // L30 is needle 71 counted from the left end (index 70); 20 stitches: L30 .. L11.
  for (const auto& [start, stop] : rig.machine.ranges()) {
    EXPECT_EQ(start, 70);
    EXPECT_EQ(stop, 89);
  }
  EXPECT_EQ(job.progress_done, 8);
  // `atelierctl show` tells the choice in the job's history.
  bool said = false;
  for (const JobEvent& e : rig.store.history(id))
    if (e.to == "running") said = e.reason.find("from row 5, needles L30 to L11") != std::string::npos;
  EXPECT_TRUE(said);
}

TEST(KnitStart, ANeedleCountedFromTheLeftEndAndOneRightOfTheCentre) {
  StartRig rig;
  const int64_t a = rig.add_job("a.png", 2);
  const int64_t b = rig.add_job("b.png", 2);
  KnitDevice& device = rig.run();
  StartOptions at_31;
  at_31.start_needle = "31";
  device.start(a, at_31);
  ASSERT_TRUE(rig.watch.wait_left(a, JobState::running));
  StartOptions at_r1;
  at_r1.start_needle = "r1";
  device.start(b, at_r1);
  ASSERT_TRUE(rig.watch.wait_left(b, JobState::running));
  ASSERT_EQ(rig.state(b), JobState::completed) << rig.store.get(b)->reason;
  const auto ranges = rig.machine.ranges();
  ASSERT_EQ(ranges.size(), 4u);
  EXPECT_EQ(ranges[0], std::make_pair(30, 49));
  EXPECT_EQ(ranges[3], std::make_pair(100, 119));  // R1 is the first needle right of the centre
}

TEST(KnitStart, TheSidecarSetsRowAndNeedleAndTheStartOptionsOverrideIt) {
  StartRig rig;
  const int64_t own = rig.add_job("own.png", 6, "autostart = true\nstart_row = 3\nstart_needle = \"R10\"\n");
  const int64_t over = rig.add_job("over.png", 6, "start_row = 3\nstart_needle = \"R10\"\n");
  KnitDevice& device = rig.run();
  ASSERT_TRUE(rig.watch.wait_left(own, JobState::running));
  ASSERT_EQ(rig.state(own), JobState::completed) << rig.store.get(own)->reason;
  EXPECT_EQ(rig.machine.recorded(), rig.expected(6, 109, 3));
  EXPECT_EQ(rig.machine.ranges().front(), std::make_pair(109, 128));
  EXPECT_EQ(rig.state(over), JobState::ready);

  StartOptions options;
  options.start_needle = "L10";  // the row stays the sidecar's
  device.start(over, options);
  ASSERT_TRUE(rig.watch.wait_left(over, JobState::running));
  ASSERT_EQ(rig.state(over), JobState::completed) << rig.store.get(over)->reason;
  const auto ranges = rig.machine.ranges();
  ASSERT_EQ(ranges.size(), 8u);
  EXPECT_EQ(ranges.back(), std::make_pair(90, 109));
  const auto rows = rig.machine.recorded();
  EXPECT_EQ(std::vector<std::string>(rows.begin() + 4, rows.end()), rig.expected(6, 90, 3));
}

TEST(KnitStart, ARowOutsideThePatternOrANeedleOffTheBedIsRefusedAndNothingStarts) {
  StartRig rig;
  const int64_t id = rig.add_job("cat.png", 6);
  KnitDevice& device = rig.run();
  auto refusal = [&](std::optional<int> row, std::optional<std::string> needle) -> std::string {
    StartOptions o;
    o.from_row = row;
    o.start_needle = needle;
    try {
      device.start(id, o);
    } catch (const BadInput& e) {
      return e.what();
    }
    return "";
  };
  const std::string tag = "job " + std::to_string(id) + ": ";
  EXPECT_EQ(refusal(7, std::nullopt), tag + "--from-row 7 is outside the pattern (rows 1 to 6)");
  EXPECT_EQ(refusal(0, std::nullopt), tag + "--from-row 0 is outside the pattern (rows 1 to 6)");
  EXPECT_EQ(refusal(std::nullopt, "R90"),
            tag + "--start-needle R90 puts the pattern's 20 stitches on needles R90 to R109, off the kh930's bed "
                  "(L100 to R100); start it on L100 to R81");
  EXPECT_THAT(refusal(std::nullopt, "L101"),
              HasSubstr(tag + "--start-needle L101 is not a needle of the kh930 (knitter): needles are named"));
  EXPECT_THAT(refusal(std::nullopt, "middle"), HasSubstr("--start-needle middle is not a needle"));
  EXPECT_THAT(refusal(std::nullopt, "0"), HasSubstr("--start-needle 0 is not a needle"));
  EXPECT_EQ(refusal(std::nullopt, "R81"), "") << "the rightmost start that fits";
  ASSERT_TRUE(rig.watch.wait_left(id, JobState::running));
  EXPECT_EQ(rig.state(id), JobState::completed);
  EXPECT_EQ(rig.machine.opened(), 1) << "only the good start opened the port";
}

TEST(KnitStart, AnAutostartJobWhoseSidecarNeedleIsOffTheBedFailsSayingSoBeforeThePortOpens) {
  StartRig rig;
  const int64_t id = rig.add_job("cat.png", 3, "autostart = true\nstart_needle = \"R95\"\n");
  rig.run();
  ASSERT_TRUE(rig.watch.wait_left(id, JobState::running));
  const Job job = *rig.store.get(id);
  EXPECT_EQ(job.state, JobState::failed);
  EXPECT_THAT(job.reason, ::testing::StartsWith("knitter: start_needle R95 puts the pattern's 20 stitches "
                                               "on needles R95 to R114, off the kh930's bed"));
  EXPECT_EQ(rig.machine.opened(), 0);
}

TEST(KnitStart, AStartOfAJobWhoseSidecarRowIsBeyondThePatternIsRefusedNamingTheKey) {
  StartRig rig;
  const int64_t id = rig.add_job("cat.png", 3, "start_row = 9\n");
  KnitDevice& device = rig.run();
  try {
    device.start(id);
    ADD_FAILURE() << "started";
  } catch (const BadInput& e) {
    EXPECT_EQ(std::string(e.what()), "job " + std::to_string(id) + ": start_row 9 is outside the pattern (rows 1 to 3)");
  }
  StartOptions fix;
  fix.from_row = 2;  // the knitter's option wins over the sidecar's row
  device.start(id, fix);
  ASSERT_TRUE(rig.watch.wait_left(id, JobState::running));
  EXPECT_EQ(rig.state(id), JobState::completed) << rig.store.get(id)->reason;
  EXPECT_EQ(rig.machine.recorded(), rig.expected(3, kCentre, 2));
}

TEST(KnitStart, ALaceJobStartsAtTheFirstPassOfItsChartRowOnTheNeedlesGiven) {
  using namespace lace::test;
  // Rows with different numbers of lace passes, so chart rows and passes do not line up.
  const lace::Chart c{{row({"yo", "k", "k", "ssk"}), knit(4), row({"k2tog", "yo", "k", "k"})}};
  StartRig rig;
  const int64_t id = rig.add_lace_job(c, 4, 3, 1, "start_needle = \"L6\"\n");
  KnitDevice& device = rig.run();
  StartOptions options;
  options.from_row = 3;  // the chart row; the needle is the job file's
  device.start(id, options);
  ASSERT_TRUE(rig.watch.wait_left(id, JobState::running));
  const Job job = *rig.store.get(id);
  ASSERT_EQ(job.state, JobState::completed) << job.reason;
  ayab::PlanParams params;
  params.start_needle = 94;  // L6
  const auto plan = ayab::plan_lace(c, 4, 3, 1, params);
  ASSERT_TRUE(plan.plan);
  size_t first = 0;  // the first pass of chart row 3
  while (plan.plan->pattern_row[first] < 2) ++first;
  std::vector<std::string> want;
  for (size_t p = first; p < plan.plan->passes.size(); ++p) {
    std::string line;
    for (int n = plan.plan->start_needle; n <= plan.plan->stop_needle; ++n)
      line.push_back(ayab::needle_selected(plan.plan->passes[p], n) ? '1' : '0');
    want.push_back(line);
  }
  EXPECT_EQ(rig.machine.recorded(), want);
  ASSERT_FALSE(rig.machine.ranges().empty());
  EXPECT_EQ(rig.machine.ranges().front(), std::make_pair(94, 94 + 12 - 1));
  StartOptions beyond;
  beyond.from_row = 4;
  const int64_t again = rig.add_lace_job(c, 4, 3, 1);
  try {
    device.start(again, beyond);
    ADD_FAILURE() << "started";
  } catch (const BadInput& e) {
    EXPECT_EQ(std::string(e.what()), "job " + std::to_string(again) + ": --from-row 4 is outside the chart (rows 1 to 3)");
  }
}

}  // namespace
}  // namespace atelier
