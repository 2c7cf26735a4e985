// A job's --set values as the store keeps them: new jobs as a JSON array of the strings given,
// old stores as the TOML text earlier versions wrote, turned back into the same overrides
// without parsing TOML in the daemon.
#include "daemon/job_sets.h"

#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <toml++/toml.h>

#include "convert/common/param_table.h"

namespace atelier {
namespace {

toml::table applied(const std::vector<std::string>& sets) {
  toml::table t;
  for (const auto& s : sets) apply_set(t, s);
  return t;
}

// What the daemon stored for these --set values before (Job::params as TOML text).
std::string legacy_text(const std::vector<std::string>& sets) {
  std::ostringstream text;
  text << applied(sets);
  return text.str();
}

TEST(JobSets, NewJobsKeepTheStringsAsGiven) {
  const std::vector<std::string> sets = {"max_float=5", "dither=atkinson", "name=it's \"mine\"",
                                         "colors=[\"#ffffff\", \"#000000\"]"};
  const std::string stored = sets_to_params(sets);
  EXPECT_EQ(stored.front(), '[');
  EXPECT_EQ(params_to_sets(stored), sets);
  EXPECT_EQ(sets_to_params({}), "");
  EXPECT_TRUE(params_to_sets("").empty());
}

TEST(JobSets, OldStoresTomlTextGivesTheSameOverrides) {
  std::string numbers = "rows=[";
  for (int i = 0; i < 80; ++i) numbers += (i ? ", " : "") + std::to_string(i * 1000);
  numbers += "]";
  const std::vector<std::vector<std::string>> cases = {
      {"max_float=5", "width=80"},
      {"dither=atkinson", "solver=gsat", "invert=true", "threshold=0.5"},
      {"colors=[\"#f4efe6\", \"#3a2a5c\"]", "work_area_mm=[400, 400]"},
      {"laser.kerf_mm=0.2", "name=it's \"quoted\""},
      {"layer={color=\"#ff0000\", speed=3, inner={deep=true}}", "passes=2"},
      {numbers},
  };
  for (const auto& sets : cases) {
    const std::string text = legacy_text(sets);
    const std::vector<std::string> back = params_to_sets(text);
    EXPECT_EQ(applied(back), applied(sets)) << "stored text:\n" << text;
  }
}

TEST(JobSets, TextThatIsNoAssignmentIsSkipped) {
  EXPECT_EQ(params_to_sets("# a comment\n\nwidth = 80\njunk\n"), std::vector<std::string>{"width=80"});
  // Text that starts like a JSON array but is none is read as old TOML text: here the header
  // of an empty table (what `--set laser={}` was stored as).
  EXPECT_EQ(params_to_sets("[laser]\n"), std::vector<std::string>{"laser={}"});
}

}  // namespace
}  // namespace atelier
