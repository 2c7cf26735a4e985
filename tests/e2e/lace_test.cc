// End to end: a lace job file dropped into the hot folder becomes a chart, instructions,
// knitout and a preview; a bad job file fails with the key it got wrong; with a knitting
// machine that takes lace (the AYAB emulator on a pseudo-terminal), the chart is knitted with
// the lace carriage pass by pass exactly as planned, and a chart the lace carriage cannot do
// fails with the reason before anything is sent. A missing start chart or a job too big to run
// fails naming the job file, line and key.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "convert/lace/lace_chart_json.h"
#include "drivers/ayab/lace_plan.h"
#include "tests/e2e/daemon_harness.h"

namespace fs = std::filesystem;
using atelier::test::DaemonProcess;
using atelier::test::read_file;
using atelier::test::TempDir;
using nlohmann::json;

namespace {

const std::string kSmall = "population = 80\ngenerations = 20\nwidth = 10\nrows = 6\n";

}  // namespace

TEST(E2ELace, AJobFileInTheHotFolderBecomesAChartAndABadOneNamesItsKey) {
  TempDir tmp;
  DaemonProcess daemon(tmp.path());
  daemon.start();
  const fs::path incoming = daemon.spool() / "incoming";
  atelier::test::write_file(tmp.path() / "swatch.toml", "kind = \"lace\"\n" + kSmall + "seed = 4\n");
  atelier::test::drop_file(tmp.path() / "swatch.toml", incoming / "swatch.toml");
  // The same in incoming/lace/, where the folder names the kind (dots in a job file's name are fine).
  atelier::test::write_file(tmp.path() / "scarf.v2.toml", kSmall + "holes = 3\n");
  atelier::test::drop_file(tmp.path() / "scarf.v2.toml", daemon.incoming("lace") / "scarf.v2.toml");
  atelier::test::write_file(tmp.path() / "typo.toml", "kind = \"lace\"\nwidht = 10\n");
  atelier::test::drop_file(tmp.path() / "typo.toml", incoming / "typo.toml");

  for (const char* name : {"swatch.toml", "scarf.v2.toml"}) {
    ASSERT_TRUE(daemon.wait_job_state(name, "completed")) << daemon.jobs().dump(2) << daemon.log();
    const json job = daemon.job_named(name);
    EXPECT_EQ(job["kind"], "lace");
    const fs::path done = daemon.spool() / "done" / std::to_string(job["id"].get<int64_t>());
    for (const char* f : {"chart.json", "chart.svg", "chart.pdf", "instructions.txt", "lace.k",
                          "preview.png", "report.json", name})
      EXPECT_TRUE(fs::exists(done / f)) << name << ": " << f;
    const atelier::LaceChartFile chart =
        atelier::lace_chart_from_json(json::parse(read_file(done / "chart.json")), "chart.json");
    EXPECT_EQ(chart.cast_on, 10);
    EXPECT_TRUE(atelier::lace::yarn_over_balance(chart.chart));
    EXPECT_TRUE(json::parse(read_file(done / "report.json"))["constraints"]["all_satisfied"].get<bool>());
  }
  ASSERT_TRUE(daemon.wait_job_state("typo.toml", "failed")) << daemon.jobs().dump(2);
  EXPECT_NE(daemon.job_named("typo.toml")["reason"].get<std::string>().find("widht"), std::string::npos)
      << daemon.job_named("typo.toml").dump();
}

namespace {

struct KnitterRig {
  TempDir tmp;
  // A knitter who hears no beep waits 5 s before pushing anyway (the emulator's default, 2 passes
  // of 3 ms, is shorter than a loaded machine's scheduling delay: the job then fails as "pushed
  // too soon", which is the emulator's impatience, not the daemon's fault).
  atelier::test::KnitEmulator emulator{3, {"--fault", "knitter-patience-ms=5000"}};
  std::unique_ptr<DaemonProcess> daemon;

  explicit KnitterRig(const std::string& lace_toml) {
    daemon = std::make_unique<DaemonProcess>(
        tmp.path(), "[lace]\n" + lace_toml + "[[device]]\nname = \"knitter\"\ndriver = \"ayab\"\nport = \"" +
                        emulator.link().string() + "\"\nmachine = \"kh930\"\nkinds = [\"knit\", \"lace\"]\n"
                        "autostart = true\n");
    daemon->start();
  }
  std::vector<std::string> recorded() const { return emulator.recorded(); }
  void drop_job(const std::string& name, const std::string& toml) {
    atelier::test::write_file(tmp.path() / name, "kind = \"lace\"\n" + toml);
    atelier::test::drop_file(tmp.path() / name, daemon->spool() / "incoming" / name);
  }
};

}  // namespace

TEST(E2ELace, TheKnittingMachineKnitsTheChartWithTheLaceCarriagePassByPass) {
  KnitterRig rig("lace_carriage = true\nrepeats_wide = 2\nrepeats_high = 1\n");
  rig.drop_job("eyelets.toml", kSmall + "seed = 3\n");
  ASSERT_TRUE(rig.daemon->wait_job_state("eyelets.toml", "completed")) << rig.daemon->jobs().dump(2) << rig.daemon->log();
  const json job = rig.daemon->job_named("eyelets.toml");
  EXPECT_EQ(job["device"], "knitter");
  const fs::path done = job["output_dir"].get<std::string>();
  const atelier::LaceChartFile chart =
      atelier::lace_chart_from_json(json::parse(read_file(done / "chart.json")), "chart.json");

  // What the needles did is what the lace plan says, pass by pass: lace-carriage transfers,
  // then two plain rows with the knit carriage, for every chart row.
  atelier::ayab::PlanParams params;
  const atelier::ayab::LacePlanResult plan =
      atelier::ayab::plan_lace(chart.chart, chart.cast_on, chart.repeats_wide, chart.repeats_high, params);
  ASSERT_TRUE(plan.problems.empty()) << plan.problems.front();
  const std::vector<std::string> rows = rig.recorded();
  ASSERT_EQ(rows.size(), plan.plan->passes.size());
  const json report = json::parse(read_file(done / "report.json"));
  EXPECT_EQ(static_cast<int>(rows.size()),
            report["machine"]["lace_passes"].get<int>() + report["machine"]["knit_passes"].get<int>());
  EXPECT_EQ(report["machine"]["knit_passes"].get<int>(), 2 * static_cast<int>(chart.chart.rows.size()));
  const int width = chart.cast_on * chart.repeats_wide;
  int selected = 0;
  for (size_t p = 0; p < rows.size(); ++p) {
    ASSERT_EQ(static_cast<int>(rows[p].size()), plan.plan->stop_needle - plan.plan->start_needle + 1);
    for (int n = 0; n < static_cast<int>(rows[p].size()); ++n) {
      const int needle = plan.plan->start_needle + n;
      const bool on = (plan.plan->passes[p][needle >> 3] >> (needle & 7)) & 1;
      EXPECT_EQ(rows[p][n], on ? '1' : '0') << "pass " << p << " needle " << needle;
      selected += on;
    }
  }
  EXPECT_EQ(plan.plan->stop_needle - plan.plan->start_needle + 1, width);
  EXPECT_GT(selected, 0) << "the chart has yarn-overs, so the lace carriage transfers";
}

TEST(E2ELace, AChartTheLaceCarriageCannotDoFailsWithTheReasonAndNothingIsSent) {
  KnitterRig rig("repeats_wide = 1\nrepeats_high = 1\n");
  // "yo, k2tog": the bottom stitch would have to slide under the top one; and row 3 widens.
  rig.drop_job("hand.toml", "generations = 0\npopulation = 4\nstart_chart = [\"k1, yo, k2tog, k1\", \"k1, yo, k3\", \"k2, k2tog, k1\"]\n");
  ASSERT_TRUE(rig.daemon->wait_job_state("hand.toml", "failed")) << rig.daemon->jobs().dump(2) << rig.daemon->log();
  const std::string reason = rig.daemon->job_named("hand.toml")["reason"];
  EXPECT_NE(reason.find("lace carriage"), std::string::npos) << reason;
  EXPECT_NE(reason.find("row 1"), std::string::npos) << reason;
  EXPECT_TRUE(rig.recorded().empty());
  const fs::path done = rig.daemon->job_named("hand.toml")["output_dir"].get<std::string>();
  const json report = json::parse(read_file(done / "report.json"));
  EXPECT_FALSE(report["machine"]["lace_carriage"].get<bool>());
  EXPECT_GE(report["machine"]["problems"].size(), 2u) << report["machine"].dump(2);
}

TEST(E2ELace, AJobFileWhoseStartChartIsMissingOrTooBigFailsNamingTheFileLineAndKey) {
  TempDir tmp;
  DaemonProcess daemon(tmp.path());
  daemon.start();
  const fs::path incoming = daemon.spool() / "incoming";
  atelier::test::write_file(tmp.path() / "missing.toml", "kind = \"lace\"\npopulation = 4\nstart_chart = \"none.json\"\n");
  atelier::test::drop_file(tmp.path() / "missing.toml", incoming / "missing.toml");
  // A file outside the spool is not read for a job (the daemon would read it with its rights).
  atelier::test::write_file(tmp.path() / "secret.txt", "root:SECRET-MARKER:20228:0:99999:7:::\n");
  atelier::test::write_file(tmp.path() / "private.toml", "kind = \"lace\"\npopulation = 4\nstart_chart = \"" +
                                                             (tmp.path() / "secret.txt").string() + "\"\n");
  atelier::test::drop_file(tmp.path() / "private.toml", incoming / "private.toml");
  atelier::test::write_file(tmp.path() / "huge.toml", "population = 100000\ngenerations = 1000\n");
  atelier::test::drop_file(tmp.path() / "huge.toml", daemon.incoming("lace") / "huge.toml");

  ASSERT_TRUE(daemon.wait_job_state("missing.toml", "failed")) << daemon.jobs().dump(2) << daemon.log();
  const std::string missing = daemon.job_named("missing.toml")["reason"];
  EXPECT_NE(missing.find("missing.toml:3: key 'start_chart': none.json: no such file"), std::string::npos)
      << missing;
  ASSERT_TRUE(daemon.wait_job_state("private.toml", "failed")) << daemon.jobs().dump(2) << daemon.log();
  const std::string outside = daemon.job_named("private.toml")["reason"];
  EXPECT_NE(outside.find("private.toml:3: key 'start_chart': " + (tmp.path() / "secret.txt").string() +
                         ": outside the spool"),
            std::string::npos)
      << outside;
  EXPECT_EQ(outside.find("SECRET-MARKER"), std::string::npos) << outside;
  // Refused before any memory is taken or any generation runs.
  ASSERT_TRUE(daemon.wait_job_state("huge.toml", "failed")) << daemon.jobs().dump(2) << daemon.log();
  const std::string huge = daemon.job_named("huge.toml")["reason"];
  EXPECT_NE(huge.find("huge.toml:2: key 'generations': 1000 generations x population 100000"), std::string::npos)
      << huge;
}
