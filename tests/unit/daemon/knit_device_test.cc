// The knitting-machine device with lace jobs: a lace job's passes reach the firmware model (a
// simulated knitter, in simulated time) as planned, and a chart the carriage cannot do fails
// before the port is opened. And a board a crashed daemon left knitting: reset through DTR and
// knitted on, or, when it cannot be reset, a job that fails within seconds saying what to do.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <condition_variable>
#include <fstream>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <functional>
#include <string>
#include <vector>

#include "algorithms/lace/chart.h"
#include "algorithms/lace/symbols.h"
#include "convert/lace/lace_chart_json.h"
#include "daemon/job_service.h"
#include "daemon/knit_device.h"
#include "drivers/ayab/knit_plan.h"
#include "drivers/ayab/lace_plan.h"
#include "tests/e2e/daemon_harness.h"
#include "tests/support/carriage_firmware.h"
#include "tests/support/job_watch.h"
#include "tests/support/knitter_config.h"
#include "tests/support/lace_test_charts.h"
#include "tests/support/log_capture.h"
#include "tests/support/simulated_knitter.h"
#include "tools/knit_emu/faults.h"

namespace atelier::ayab {
namespace {

using lace::Chart;
using lace::Row;
using lace::Symbol;
using namespace lace::test;  // row(), knit(), expected_fabric() of lace_test_charts.h
// A ready job and a knitting-machine device taking knit and lace jobs, all on one FakeClock:
// the device's sessions knit against a simulated knitter in simulated time.
struct JobOnDevice {
  test::TempDir tmp;
  SpoolLayout layout{tmp.path() / "spool"};
  Store store{tmp.path() / "jobs.sqlite"};
  FakeClock clock;
  test::JobWatch watch{clock};
  // What the job's reason and the device's detail said, in order (each change and progress).
  struct Said {
    std::string reason, detail;
  };
  std::mutex said_mu;
  std::vector<Said> said;
  const DeviceWorker* device_now = nullptr;
  // Times the job left the running state (each run ends with one), for a run after a run.
  int runs_ended = 0;
  std::condition_variable_any run_ended;
  // Until the job has left running `n` times in all (at most an hour of the clock).
  bool wait_runs_ended(int n) {
    std::unique_lock lock(said_mu);
    return clock.wait_for(run_ended, lock, std::chrono::hours(1), [&] { return runs_ended >= n; });
  }
  JobService jobs{store, layout, [this, forward = watch.listener()](const JobChange& c) {
    {
      std::lock_guard lock(said_mu);
      if (c.from == "running" && c.to != "running") {
        ++runs_ended;
        run_ended.notify_all();
      }
      const std::string detail = device_now ? device_now->describe().value("detail", "") : "";
      if (said.empty() || said.back().reason != c.job.reason || said.back().detail != detail)
        said.push_back({c.job.reason, detail});
    }
    forward(c);
  }};
  int64_t id = 0;

  // A job of `kind` in `state` whose output folder `write_outputs` fills.
  JobOnDevice(const std::string& kind, const std::string& name, JobState state,
              const std::function<void(const std::string& dir)>& write_outputs) {
    jobs.ensure_layout();
    Job job;
    job.id = store.reserve_id();
    job.kind = kind;
    job.name = name;
    job.state = state;
    job.output_dir = (tmp.path() / "done" / std::to_string(job.id)).string();
    std::filesystem::create_directories(job.output_dir);
    write_outputs(job.output_dir);
    store.insert_job(job);
    id = job.id;
  }
  // Runs the device on `machine` until it is done with the job (at most an hour of the clock);
  // `resume_from` resumes an interrupted job from that chart row first; the job is canceled
  // once `cancel_when` says so (asked each time the machine has knitted a row).
  Job run(test::SimulatedKnitter& machine, int resume_from = 0, const std::function<bool()>& cancel_when = {}) {
    const DeviceConfig d = test::knitter_device_config(/*autostart=*/true);
    KnitDevice device(
        d, jobs, [&machine](const std::string&) { return machine.open(); },
        [port = d.port]() -> std::optional<std::string> { return port; }, {}, clock);
    bool canceled = false;
    machine.on_row = [&] {
      if (cancel_when && !canceled && cancel_when()) canceled = device.cancel(id);
    };
    int before = 0;
    {
      std::lock_guard lock(said_mu);
      before = runs_ended;
    }
    if (resume_from > 0) device.resume(id, resume_from);
    device.start_worker();
    device.wake();
    EXPECT_TRUE(wait_runs_ended(before + 1)) << "the device did not finish the job";
    device.stop();
    machine.on_row = nullptr;
    return *store.get(id);
  }
};

// The same on a machine behind `open` (a fresh board each time, e.g. CarriageFirmware).
Job run_on(JobOnDevice& rig, const KnitDevice::Opener& open, int resume_from = 0) {
  const DeviceConfig d = test::knitter_device_config(/*autostart=*/true);
  KnitDevice device(d, rig.jobs, open, [port = d.port]() -> std::optional<std::string> { return port; }, {},
                    rig.clock);
  rig.device_now = &device;
  int before = 0;
  {
    std::lock_guard lock(rig.said_mu);
    before = rig.runs_ended;
  }
  if (resume_from > 0) device.resume(rig.id, resume_from);
  device.start_worker();
  device.wake();
  EXPECT_TRUE(rig.wait_runs_ended(before + 1)) << "the device did not finish the job";
  device.stop();
  rig.device_now = nullptr;
  return *rig.store.get(rig.id);
}

// Boards that boot afresh on each open (an Uno resets when its port opens), each following
// `script`; the latest is last.
struct Boards {
  explicit Boards(FakeClock& c) : clock(c) {}
  FakeClock& clock;
  test::CarriageScript script;
  std::vector<std::shared_ptr<test::CarriageFirmware>> boards;
  KnitDevice::Opener opener() {
    return [this](const std::string&) -> std::unique_ptr<Transport> {
      boards.push_back(std::make_shared<test::CarriageFirmware>(script));
      return std::make_unique<SimulatedTransport>(boards.back(), clock);
    };
  }
};

// A ready lace job (chart.json in its output folder) on the device.
struct LaceJobOnDevice : JobOnDevice {
  LaceJobOnDevice(const Chart& chart, int cast_on, int wide, int high, JobState state = JobState::ready)
      : JobOnDevice("lace", "lace.toml", state, [&](const std::string& dir) {
          std::ofstream(dir + "/chart.json") << lace_chart_to_json({chart, cast_on, wide, high}).dump();
        }) {}
};

// A ready knit job on the device: pattern.png, `rows` rows of 20 stitches with one contrast
// stitch each.
cv::Mat knit_pattern(int rows) {
  cv::Mat pattern(rows, 20, CV_8UC1, cv::Scalar(255));
  for (int r = 0; r < rows; ++r) pattern.at<uint8_t>(r, (r * 3) % 20) = 0;
  return pattern;
}
struct KnitJobOnDevice : JobOnDevice {
  explicit KnitJobOnDevice(int rows)
      : JobOnDevice("knit", "pattern.png", JobState::ready, [rows](const std::string& dir) {
          cv::imwrite(dir + "/pattern.png", knit_pattern(rows));
        }) {}
};

// Needle strings (working range, leftmost first) of the plan's passes from `from_pass` on: what
// the simulated knitter records.
std::vector<std::string> pass_lines(const KnitPlan& plan, size_t from_pass = 0) {
  std::vector<std::string> out;
  for (size_t p = from_pass; p < plan.passes.size(); ++p) {
    std::string line;
    for (int n = plan.start_needle; n <= plan.stop_needle; ++n) line.push_back(needle_selected(plan.passes[p], n) ? '1' : '0');
    out.push_back(line);
  }
  return out;
}

// The plan the device makes of knit_pattern(rows).
KnitPlan knit_job_plan(int rows) {
  cv::Mat stitches = knit_pattern(rows) < 128;
  stitches /= 255;
  return plan_knitting(stitches, PlanParams{});
}

TEST(AyabKnitPrompts, TheKnitterIsToldWhatToDoInOrderAndTheJobEndsAfterTheLastPass) {
  KnitJobOnDevice rig(3);
  Boards boards{rig.clock};
  const Job job = run_on(rig, boards.opener());
  ASSERT_EQ(job.state, JobState::completed) << job.reason;
  const std::string tag = "job " + std::to_string(rig.id) + ": ";
  std::vector<std::string> reasons;
  for (const auto& s : rig.said) {
    reasons.push_back(s.reason);
    if (s.reason.rfind("knitting on", 0) != 0 && s.reason.rfind("knitted 3 rows", 0) != 0) {
      EXPECT_EQ(s.detail, tag + s.reason) << "the device says what the job says";
    }
  }
  const std::string one_more =
      "all 3 rows knitted; one more pass to finish: move the carriage across once more (the machine beeps twice)";
  EXPECT_EQ(reasons, (std::vector<std::string>{"knitting on knitter",
                                               "move the carriage over the left turn mark (set it to KC-I or KC-II)",
                                               "knitting row 1 of 3", "knitting row 2 of 3", "knitting row 3 of 3",
                                               "knitted row 3 of 3", one_more, "knitted 3 rows on knitter"}));
  // Completed once the carriage made the blank line's pass, not when the line was sent.
  ASSERT_EQ(boards.boards.size(), 1u);
  EXPECT_EQ(boards.boards[0]->passes().size(), 4u);
  EXPECT_EQ(boards.boards[0]->state(), FsmState::init);
}

TEST(AyabKnitGarbledLine, ARowKnittedFromAGarbledLineInterruptsTheJobNamingItAndResumeFinishes) {
  KnitJobOnDevice rig(5);
  Boards boards{rig.clock};
  boards.script.garble_first_copy_of = 2;  // row 3
  Job job = run_on(rig, boards.opener());
  ASSERT_EQ(job.state, JobState::interrupted) << job.reason;
  EXPECT_EQ(job.progress_done, 2) << "the garbled row was counted as knitted";
  EXPECT_THAT(job.reason, ::testing::StartsWith("row 3 was knitted from a line garbled on the cable"));
  EXPECT_THAT(job.reason, ::testing::HasSubstr("unravel that row, then continue with: atelierctl resume " +
                                               std::to_string(rig.id) + " --from-row 3"));
  const KnitPlan plan = knit_job_plan(5);
  const auto want = pass_lines(plan);
  ASSERT_EQ(boards.boards.size(), 1u);
  const auto& first = boards.boards[0]->passes();
  ASSERT_EQ(first.size(), 3u);
  EXPECT_EQ(std::vector<std::string>(first.begin(), first.begin() + 2), std::vector<std::string>(want.begin(), want.begin() + 2));
  EXPECT_NE(first[2], want[2]);

  boards.script.garble_first_copy_of = -1;
  job = run_on(rig, boards.opener(), 3);
  ASSERT_EQ(job.state, JobState::completed) << job.reason;
  ASSERT_EQ(boards.boards.size(), 2u);
  auto second = boards.boards[1]->passes();
  ASSERT_EQ(second.size(), 4u);  // rows 3..5 and the blank pass
  second.pop_back();
  EXPECT_EQ(second, pass_lines(plan, 2));
}

TEST(AyabKnitHungBoard, AHungBoardIsResetThroughDtrAndResumeWorksWithoutAReplug) {
  KnitJobOnDevice rig(6);
  Boards boards{rig.clock};
  boards.script.hang_at_line = 3;  // asking for row 4: rows 1..3 are knitted
  Job job = run_on(rig, boards.opener());
  ASSERT_EQ(job.state, JobState::interrupted) << job.reason;
  EXPECT_EQ(job.progress_done, 3);
  EXPECT_EQ(job.reason, "the knitting machine stopped answering after row 3 (its firmware hung, e.g. on a byte "
                        "garbled on the cable); atelier reset it; continue with: atelierctl resume " +
                            std::to_string(rig.id) + " --from-row 4");
  ASSERT_EQ(boards.boards.size(), 1u);
  EXPECT_EQ(boards.boards[0]->dtr_pulses(), 1);
  EXPECT_FALSE(boards.boards[0]->hung()) << "the reset did not bring the board back";

  boards.script.hang_at_line = -1;
  job = run_on(rig, boards.opener(), 4);
  ASSERT_EQ(job.state, JobState::completed) << job.reason;
  auto second = boards.boards.back()->passes();
  ASSERT_EQ(second.size(), 4u);
  second.pop_back();
  EXPECT_EQ(second, pass_lines(knit_job_plan(6), 3));
}

TEST(AyabKnitHungBoard, ABoardThatHangsBeforeTheCarriageCrossesTheTurnMarkIsResetAndKnits) {
  KnitJobOnDevice rig(3);
  Boards boards{rig.clock};
  boards.script.hang_before_ready = true;
  const Job job = run_on(rig, boards.opener());
  ASSERT_EQ(job.state, JobState::completed) << job.reason;
  ASSERT_EQ(boards.boards.size(), 1u);
  EXPECT_EQ(boards.boards[0]->dtr_pulses(), 1);
  EXPECT_EQ(boards.boards[0]->passes().size(), 4u);
}

TEST(AyabKnitHungBoard, ABoardStillHungAfterTheResetSaysToUnplugIt) {
  KnitJobOnDevice rig(6);
  Boards boards{rig.clock};
  boards.script.hang_at_line = 2;
  boards.script.hang_survives_reset = true;
  const Job job = run_on(rig, boards.opener());
  ASSERT_EQ(job.state, JobState::interrupted) << job.reason;
  EXPECT_THAT(job.reason, ::testing::HasSubstr("stopped answering after row 2"));
  EXPECT_THAT(job.reason, ::testing::HasSubstr("atelier reset it, but it still does not answer: unplug it and plug "
                                               "it back; continue with: atelierctl resume " +
                                               std::to_string(rig.id) + " --from-row 3"));
}

// The same faults on the firmware model (tools/knit_emu/firmware.h, followed by the emulator).
TEST(AyabKnitGarbledLine, OnTheFirmwareModelAGarbledRowIsNeverCountedAndResumeFinishesTheFabric) {
  KnitJobOnDevice rig(6);
  knit_emu::Faults faults;
  ASSERT_EQ(knit_emu::apply_fault("corrupt-line=3", faults), "");  // row 3's line
  test::SimulatedKnitter machine(rig.clock, 20, faults);
  Job job = rig.run(machine);
  ASSERT_EQ(job.state, JobState::interrupted) << job.reason;
  EXPECT_EQ(job.progress_done, 2);
  EXPECT_THAT(job.reason, ::testing::StartsWith("row 3 was knitted from a line garbled on the cable"));
  EXPECT_THAT(job.reason, ::testing::HasSubstr("--from-row 3"));
  const auto want = pass_lines(knit_job_plan(6));
  const auto garbled = machine.recorded();
  ASSERT_GE(garbled.size(), 3u);
  EXPECT_EQ(std::vector<std::string>(garbled.begin(), garbled.begin() + 2),
            std::vector<std::string>(want.begin(), want.begin() + 2));
  EXPECT_NE(garbled[2], want[2]);
  job = rig.run(machine, 3);
  ASSERT_EQ(job.state, JobState::completed) << job.reason;
  const auto all = machine.recorded();
  ASSERT_EQ(all.size(), garbled.size() + 4);
  EXPECT_EQ(std::vector<std::string>(all.begin() + static_cast<long>(garbled.size()), all.end()),
            std::vector<std::string>(want.begin() + 2, want.end()));
}

TEST(AyabKnitHungBoard, OnTheFirmwareModelAHungBoardIsResetAndResumeFinishesTheFabric) {
  KnitJobOnDevice rig(6);
  knit_emu::Faults faults;
  ASSERT_EQ(knit_emu::apply_fault("bad-escape-after-row=3", faults), "");
  test::SimulatedKnitter machine(rig.clock, 20, faults);
  Job job = rig.run(machine);
  ASSERT_EQ(job.state, JobState::interrupted) << job.reason;
  EXPECT_EQ(job.reason, "the knitting machine stopped answering after row 3 (its firmware hung, e.g. on a byte "
                        "garbled on the cable); atelier reset it; continue with: atelierctl resume " +
                            std::to_string(rig.id) + " --from-row 4");
  EXPECT_EQ(machine.dtr_pulses(), 1);
  job = rig.run(machine, 4);
  ASSERT_EQ(job.state, JobState::completed) << job.reason;
  EXPECT_EQ(machine.recorded(), pass_lines(knit_job_plan(6)));
}

TEST(AyabLacePlanOnTheMachine, AChartTheCarriageCannotDoFailsBeforeThePortOpens) {
  // Two problems: the yarn-over before a k2tog (row 3), and a row that widens (row 5).
  const Chart c{{knit(4), row({"k", "yo", "k2tog", "k"}), row({"yo", "k", "k", "k", "k"})}};
  LaceJobOnDevice rig(c, 4, 2, 1);
  test::SimulatedKnitter machine(rig.clock, 2);
  const Job job = rig.run(machine);
  EXPECT_EQ(job.state, JobState::failed);
  EXPECT_EQ(job.reason.rfind("the lace carriage cannot knit this chart: row 3 (RS), stitch 3 (k2tog)", 0), 0u)
      << job.reason;
  EXPECT_NE(job.reason.find("; 1 more in report.json"), std::string::npos) << job.reason;
  EXPECT_EQ(machine.opened(), 0);
}

// A knit job whose report says it is not knittable as is (an incomplete
// solution: floats over the limit) fails before the port opens, with the report's reason.
TEST(AyabKnitRefusal, AJobNotKnittableAsIsFailsWithTheReasonAndNothingIsSent) {
  const std::string warning = "not knittable as is: floats up to 14 needles, limit 4 (solver \"none\" left 9 violations)";
  JobOnDevice rig("knit", "pattern.png", JobState::ready, [&](const std::string& dir) {
    cv::imwrite(dir + "/pattern.png", knit_pattern(3));
    std::ofstream(dir + "/report.json") << nlohmann::json{{"kind", "knit"}, {"knittable", false},
                                                          {"warnings", {warning}}}.dump();
  });
  test::SimulatedKnitter machine(rig.clock, 2);
  const Job job = rig.run(machine);
  EXPECT_EQ(job.state, JobState::failed);
  EXPECT_EQ(job.reason, "refused: " + warning + "; convert it again with a complete solver");
  EXPECT_EQ(machine.opened(), 0);
}

TEST(AyabKnitRefusal, AKnittableReportKnits) {
  JobOnDevice rig("knit", "pattern.png", JobState::ready, [&](const std::string& dir) {
    cv::imwrite(dir + "/pattern.png", knit_pattern(3));
    std::ofstream(dir + "/report.json") << nlohmann::json{{"kind", "knit"}, {"knittable", true},
                                                          {"warnings", nlohmann::json::array()}}.dump();
  });
  Boards boards{rig.clock};
  const Job job = run_on(rig, boards.opener());
  EXPECT_EQ(job.state, JobState::completed) << job.reason;
}

TEST(AyabLacePlanOnTheMachine, ALaceJobSendsEveryPlannedPass) {
  const Chart c{{row({"k", "yo", "sk2p", "yo", "k"}), knit(5), row({"yo", "k", "ssk", "k", "k"}), knit(5)}};
  LaceJobOnDevice rig(c, 5, 4, 2);
  test::SimulatedKnitter emulator(rig.clock, 2);
  const Job job = rig.run(emulator);
  ASSERT_EQ(job.state, JobState::completed) << job.reason;
  EXPECT_EQ(job.progress_done, 8);  // chart rows, repeats_high included
  EXPECT_EQ(job.progress_total, 8);
  EXPECT_EQ(emulator.opened(), 1);

  const auto plan = plan_lace(c, 5, 4, 2, {});
  ASSERT_TRUE(plan.plan);
  EXPECT_EQ(emulator.recorded(), pass_lines(*plan.plan));
}

TEST(AyabLacePlanOnTheMachine, ResumeFromAChartRowStartsAtThatRowsFirstPass) {
  // Rows with different numbers of lace passes, so rows and passes do not line up.
  const Chart c{{row({"yo", "k", "k", "ssk"}), knit(4), row({"k2tog", "yo", "k", "k"})}};
  LaceJobOnDevice rig(c, 4, 3, 2, JobState::interrupted);
  test::SimulatedKnitter emulator(rig.clock, 2);
  const Job job = rig.run(emulator, 4);
  ASSERT_EQ(job.state, JobState::completed) << job.reason;
  EXPECT_EQ(job.progress_done, 6);
  const auto plan = plan_lace(c, 4, 3, 2, {});
  ASSERT_TRUE(plan.plan);
  size_t first = 0;  // the first pass of chart row 4 (0-based 3)
  while (plan.plan->pattern_row[first] < 3) ++first;
  EXPECT_EQ(emulator.recorded(), pass_lines(*plan.plan, first));
}

TEST(AyabLacePlanOnTheMachine, ACanceledLaceJobStopsWhereAChartRowBegins) {
  const Chart c{{row({"yo", "k", "k", "ssk"}), knit(4)}};
  const auto plan = plan_lace(c, 4, 3, 2, {});
  ASSERT_TRUE(plan.plan);
  size_t row1 = 0;  // passes of chart row 1: lace-carriage transfers, then the two knit rows
  while (plan.plan->pattern_row[row1] == 0) ++row1;
  ASSERT_GE(row1, 5u);
  LaceJobOnDevice rig(c, 4, 3, 2);
  test::SimulatedKnitter emulator(rig.clock, 150);
  // Canceled the moment the first transfer pass is done, in the middle of chart row 1:
  // stopping there would leave the stitches moved but unknitted (and a resume from row 1
  // would move them again).
  const Job job = rig.run(emulator, 0, [&] { return !emulator.recorded().empty(); });
  EXPECT_EQ(job.state, JobState::canceled) << job.reason;
  EXPECT_EQ(job.progress_done, 1);
  std::vector<std::string> row_one = pass_lines(*plan.plan, 0);
  row_one.resize(row1);
  EXPECT_EQ(emulator.recorded(), row_one) << "all of chart row 1, nothing of row 2"
      << " (row 1 has " << row1 << " passes)";
}

TEST(AyabLacePlanOnTheMachine, ALinkLostInTheMiddleOfAChartRowSaysSoWithTheResumeHint) {
  // Unplugged after the second pass of chart row 1 (8 passes: transfers, then two knit rows).
  const Chart c{{row({"yo", "k", "k", "ssk"}), knit(4)}};
  LaceJobOnDevice rig(c, 4, 3, 2);
  knit_emu::Faults faults;
  ASSERT_EQ(knit_emu::apply_fault("drop-after-row=2:60000", faults), "");
  test::SimulatedKnitter emulator(rig.clock, 5, faults);
  const Job job = rig.run(emulator);
  ASSERT_EQ(job.state, JobState::interrupted) << job.reason;
  EXPECT_EQ(job.progress_done, 0);
  // Resuming chart row 1 as planned would move the moved stitches again: the reason says so.
  EXPECT_THAT(job.reason, ::testing::HasSubstr("chart row 1 stopped after "));
  EXPECT_THAT(job.reason, ::testing::HasSubstr("of its 8 passes: its stitches may be moved but not knitted; put "
                                               "them back as the cast-on left them"));
  EXPECT_THAT(job.reason, ::testing::HasSubstr("--from-row 1"));
}

// A daemon killed in the middle of a job leaves the firmware knitting: here it got as far as the
// start, and the board was not reset when the port closed (or opened).
void leave_knitting(test::SimulatedKnitter& machine, FakeClock& clock) {
  auto link = machine.open();
  HostSession crashed(*link, {}, clock);
  crashed.connect();
  crashed.init(MachineType::kh930);
  cv::Mat stitches = knit_pattern(3) < 128;  // 1 = contrast, as the device plans it
  stitches /= 255;
  crashed.start(plan_knitting(stitches, PlanParams{}));
  ASSERT_EQ(machine.firmware().state(), FsmState::knit);
}  // the link goes without a word: no last line

TEST(AyabResetOnTheMachine, ABoardLeftKnittingByACrashedDaemonIsResetThroughDtrAndTheNextJobKnits) {
  KnitJobOnDevice rig(4);
  // The board resets on a DTR pulse, but the port was closed without dropping DTR (no HUPCL),
  // so opening it did not reset it.
  test::SimulatedKnitter machine(rig.clock, 2, {}, 50, test::SimulatedKnitter::Wiring::on_pulse_only);
  leave_knitting(machine, rig.clock);
  test::LogCapture captured;
  const Job job = rig.run(machine);
  ASSERT_EQ(job.state, JobState::completed) << job.reason;
  EXPECT_EQ(machine.dtr_pulses(), 1);
  // The reset is part of the job's story in the journal: logged with the job's fields.
  const std::vector<log::Record> records = captured.for_job(rig.id);
  ASSERT_EQ(records.size(), 1u);
  EXPECT_THAT(records[0].message, ::testing::HasSubstr("resetting the board (DTR) and trying once more"));
  EXPECT_EQ(records[0].fields.kind, "knit");
  EXPECT_EQ(records[0].fields.device, "knitter");
  EXPECT_EQ(machine.recorded().size(), 4u) << "every row of the new job, nothing of the old one";
}

TEST(AyabResetOnTheMachine, ABoardThatCannotBeResetFailsTheJobWithinSecondsSayingWhatToDo) {
  KnitJobOnDevice rig(4);
  knit_emu::Faults faults;
  ASSERT_EQ(knit_emu::apply_fault("no-dtr-reset", faults), "");
  test::SimulatedKnitter machine(rig.clock, 2, faults);
  leave_knitting(machine, rig.clock);
  const auto t0 = rig.clock.now();
  const Job job = rig.run(machine);
  const auto took = rig.clock.now() - t0;
  ASSERT_EQ(job.state, JobState::failed) << job.reason;
  EXPECT_THAT(job.reason, ::testing::StartsWith("knitter: the knitting machine refused to start: wrong machine state "
                                                "(0xef)"));
  EXPECT_THAT(job.reason, ::testing::HasSubstr("not reset"));
  EXPECT_THAT(job.reason, ::testing::HasSubstr("reset it (the reset button on its Arduino"));
  EXPECT_EQ(machine.dtr_pulses(), 1) << "one reset tried before giving up";
  EXPECT_LT(took, std::chrono::seconds(5)) << "the job hung instead of failing";
  // The knitter may push the carriage over the old session's blank buffer meanwhile; nothing of
  // the new job was knitted.
  for (const std::string& row : machine.recorded()) EXPECT_EQ(row.find('1'), std::string::npos) << row;
}

}  // namespace
}  // namespace atelier::ayab
