// atelierctl's renderings (tools/ctl_format.h): what an operator reads for devices, show,
// watch, command confirmations, a cut list and cancel --all. TZ is set to UTC so local times
// are predictable.
#include "tools/ctl_format.h"

#include <gtest/gtest.h>
#include <stdlib.h>
#include <time.h>

#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace atelier::ctl {
namespace {

using nlohmann::json;

class CtlFormatTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* tz = getenv("TZ");
    if (tz != nullptr) saved_tz_ = tz;
    had_tz_ = tz != nullptr;
    setenv("TZ", "UTC", 1);
    tzset();
  }
  void TearDown() override {
    if (had_tz_) {
      setenv("TZ", saved_tz_.c_str(), 1);
    } else {
      unsetenv("TZ");
    }
    tzset();
  }

 private:
  std::string saved_tz_;
  bool had_tz_ = false;
};

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

json laser_device(const json& job, const std::string& last, const std::string& detail) {
  return {{"name", "laser"}, {"driver", "grbl"},   {"port", "/dev/atelier/laser"},
          {"state", "busy"}, {"job", job},          {"last", last},
          {"detail", detail}};
}

TEST_F(CtlFormatTest, StatusGivesTheWebPagesAddressOrWhyItIsNotThere) {
  json status = {{"version", "0.1.0"}, {"spool", "/var/spool/atelier"}, {"queue", json::object()},
                 {"devices", json::array()},
                 {"web", {{"enabled", true}, {"listen", "127.0.0.1:8631"}, {"listening", true},
                          {"url", "http://127.0.0.1:8631/"}}}};
  EXPECT_NE(format_status(status).find("web:     http://127.0.0.1:8631/\n"), std::string::npos) << format_status(status);
  status["web"] = {{"enabled", true}, {"listen", "127.0.0.1:8631"}, {"listening", false},
                   {"error", "web: cannot listen on 127.0.0.1:8631: the address is in use"}};
  EXPECT_NE(format_status(status).find("web:     not listening on 127.0.0.1:8631: web: cannot listen"), std::string::npos)
      << format_status(status);
  status["web"] = {{"enabled", false}};
  EXPECT_EQ(format_status(status).find("web:"), std::string::npos);
}

TEST_F(CtlFormatTest, DevicesShowLastAndDetailColumns) {
  json running = {{"id", 7},
                  {"name", "box.svg"},
                  {"progress", {{"done", 40}, {"total", 80}, {"unit", "lines"}}}};
  const std::string out = format_devices(json::array(
      {laser_device(running, "framed job 7 with the beam off", "job 7: line 40 of 80, 6 s left"),
       {{"name", "knitter"}, {"driver", "ayab"}, {"port", "/dev/ttyACM0"}, {"state", "online"},
        {"job", nullptr}, {"last", ""}, {"detail", ""}}}));
  const auto lines = lines_of(out);
  ASSERT_EQ(lines.size(), 3u) << out;
  EXPECT_NE(lines[0].find("LAST"), std::string::npos) << out;
  EXPECT_NE(lines[0].find("DETAIL"), std::string::npos) << out;
  EXPECT_NE(lines[1].find("framed job 7 with the beam off"), std::string::npos) << out;
  EXPECT_NE(lines[1].find("job 7: line 40 of 80, 6 s left"), std::string::npos) << out;
  // An idle device shows dashes (JOB, LAST, DETAIL), not blanks that shift the columns.
  std::istringstream words(lines[2]);
  std::vector<std::string> cells;
  for (std::string w; words >> w;) cells.push_back(w);
  ASSERT_EQ(cells.size(), 7u) << lines[2];
  EXPECT_EQ(cells[4], "-");
  EXPECT_EQ(cells[5], "-");
  EXPECT_EQ(cells[6], "-");
}

TEST_F(CtlFormatTest, DevicesCountLaserProgressInLinesAndKnittingInRows) {
  json laser_job = {{"id", 7}, {"progress", {{"done", 40}, {"total", 80}, {"unit", "lines"}}}};
  json knit_job = {{"id", 3}, {"progress", {{"done", 12}, {"total", 120}, {"unit", "rows"}}}};
  const std::string out = format_devices(
      json::array({laser_device(laser_job, "", ""), laser_device(knit_job, "", "")}));
  EXPECT_NE(out.find("7 (40/80 lines)"), std::string::npos) << out;
  EXPECT_EQ(out.find("40/80 rows"), std::string::npos) << out;
  EXPECT_NE(out.find("3 (12/120 rows)"), std::string::npos) << out;
}

TEST_F(CtlFormatTest, ShowPrintsTheEstimateAndTheTimeLeft) {
  json job = {{"id", 7},
              {"kind", "cut"},
              {"name", "box.svg"},
              {"state", "running"},
              {"progress", {{"done", 40}, {"total", 80}, {"unit", "lines"}}},
              {"estimated_s", 754.2},
              {"time_left_s", 65}};
  const std::string out = format_job_details(job);
  EXPECT_NE(out.find("progress:"), std::string::npos) << out;
  EXPECT_NE(out.find("40/80 lines"), std::string::npos) << out;
  EXPECT_NE(out.find("estimated: 12m 34s"), std::string::npos) << out;
  EXPECT_NE(out.find("time left: 1m 05s"), std::string::npos) << out;
}

TEST_F(CtlFormatTest, ConversionProgressIsAPercentage) {
  json job = {{"id", 5}, {"kind", "knit"}, {"name", "cat.png"}, {"state", "converting"},
              {"updated", "2024-05-01T12:00:00Z"},
              {"progress", {{"done", 30}, {"total", 100}, {"unit", "percent"}}}};
  EXPECT_NE(format_job_table(json::array({job})).find("30%"), std::string::npos);
}

TEST_F(CtlFormatTest, EachWatchLineCarriesTheTimeOfItsOwnEvent) {
  // Two progress steps of one laser job: the job's "updated" is its last state change.
  json job = {{"id", 7}, {"name", "box.svg"}, {"state", "running"},
              {"updated", "2024-05-01T12:00:00.000Z"}};
  json first = {{"at", "2024-05-01T12:00:01.200Z"}, {"job", job}, {"from", "running"},
                {"to", "running"}, {"reason", "line 10 of 80, 5 s left"}, {"progress", true}};
  json later = first;
  later["at"] = "2024-05-01T12:00:05.900Z";
  later["reason"] = "line 70 of 80, 1 s left";
  EXPECT_EQ(format_event(first), "2024-05-01 12:00:01 job 7 box.svg: running, line 10 of 80, 5 s left\n");
  EXPECT_EQ(format_event(later), "2024-05-01 12:00:05 job 7 box.svg: running, line 70 of 80, 1 s left\n");
}

TEST_F(CtlFormatTest, AConfirmationShowsWhatTheCommandSetUnderWay) {
  json job = {{"id", 2}, {"name", "box.svg"}, {"state", "ready"},
              {"reason", "converted; waiting for laser and `atelierctl start 2`"},
              {"effect", "armed (runs on laser as soon as it is free)"}};
  EXPECT_EQ(format_job_line(job), "job 2 box.svg: ready, armed (runs on laser as soon as it is free)\n");
  job.erase("effect");
  job["state"] = "running";
  job["reason"] = "running on laser";
  EXPECT_EQ(format_job_line(job), "job 2 box.svg: running (running on laser)\n");
}

TEST_F(CtlFormatTest, ACutListSaysHowManyJobsThereAre) {
  json jobs = json::array({{{"id", 3}}, {{"id", 2}}});
  EXPECT_EQ(list_cut_note({{"jobs", jobs}, {"total", 1532}}),
            "showing 2 of 1532 jobs; --all for every job\n");
  EXPECT_EQ(list_cut_note({{"jobs", jobs}, {"total", 2}}), "");
  EXPECT_EQ(list_cut_note(jobs), "");  // an older daemon's bare array: nothing to say
}

TEST_F(CtlFormatTest, CancelAllListsTheJobsAndCountsThem) {
  json result = {{"jobs",
                  {{{"id", 4}, {"name", "a.svg"}, {"state", "canceled"}, {"reason", "canceled by user"}},
                   {{"id", 3},
                    {"name", "cat.png"},
                    {"state", "running"},
                    {"reason", "running on knitter"},
                    {"effect", "canceling (the machine stops after the row being knitted)"}}}},
                 {"canceled", 2},
                 {"stopping", 1}};
  EXPECT_EQ(lines_of(format_cancel_all(result)),
            (std::vector<std::string>{
                "job 4 a.svg: canceled (canceled by user)",
                "job 3 cat.png: running, canceling (the machine stops after the row being knitted)",
                "canceled 2 jobs (1 still stopping)"}));
  EXPECT_EQ(format_cancel_all({{"jobs", json::array()}, {"canceled", 0}, {"stopping", 0}}),
            "no unfinished jobs to cancel\n");
}

TEST_F(CtlFormatTest, LaserCommandsShowEachLineSentWithItsRepliesAndTheLogOldestFirst) {
  const json unlocked = {{"device", "laser"},
                         {"effect", "unlocked ($X)"},
                         {"lines", json::array({{{"sent", "$X"}, {"reply", {"[MSG:Caution: Unlocked]", "ok"}}}})}};
  EXPECT_EQ(format_laser(unlocked), "> $X\n  [MSG:Caution: Unlocked]\n  ok\nlaser: unlocked ($X)\n");
  const json log = {{"lines", json::array({{{"at", "2026-12-02T12:00:01.000Z"}, {"device", "laser"}, {"uid", 1000},
                                            {"line", "$$"}, {"reply", "$0=10\nok"}},
                                           {{"at", "2026-12-02T12:00:05.000Z"}, {"device", "laser"}, {"uid", 0},
                                            {"line", "G0X5"}, {"reply", "error:9"}}})}};
  EXPECT_EQ(lines_of(format_laser(log)),
            (std::vector<std::string>{"2026-12-02 12:00:01  laser  uid 1000> $$", "  $0=10", "  ok",
                                      "2026-12-02 12:00:05  laser  uid 0> G0X5", "  error:9"}));
  EXPECT_EQ(format_laser(json{{"lines", json::array()}}), "no console lines\n");
}

}  // namespace
}  // namespace atelier::ctl
