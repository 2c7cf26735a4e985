// Shared by the job store's tests: every job state, the allowed edges written out independently
// of the code, and the StoreTest fixture (a scratch folder per test, jobs driven along edges).
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <deque>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "daemon/store.h"

namespace atelier::test {

namespace fs = std::filesystem;
using S = JobState;

inline const std::vector<JobState> kAllStates = {S::queued,    S::converting, S::ready,
                                                 S::running,   S::completed,  S::failed,
                                                 S::canceled,  S::interrupted};

// The edges DESIGN.md "Job states" and store.h allow, written out independently of the code.
inline const std::set<std::pair<JobState, JobState>> kAllowed = {
    {S::queued, S::converting},     {S::queued, S::canceled},
    {S::queued, S::failed},  // rejected at pick-up (symlink, unknown kind, ...)
    {S::converting, S::ready},      {S::converting, S::completed},
    {S::converting, S::failed},     {S::converting, S::canceled},
    {S::converting, S::queued},     {S::ready, S::running},
    {S::ready, S::completed},       {S::ready, S::canceled},
    {S::running, S::completed},     {S::running, S::failed},
    {S::running, S::canceled},      {S::running, S::interrupted},
    {S::failed, S::queued},         {S::interrupted, S::queued},
    {S::canceled, S::queued},       {S::interrupted, S::running},
};

class StoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("atelier-store-" + std::to_string(getpid()) + "-" +
                                        info->test_suite_name() + "-" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // In a folder that does not exist yet: the Store must create it.
  fs::path db_path() const { return dir_ / "state" / "jobs.sqlite"; }

  static Job make_job(int64_t id, const std::string& kind, const std::string& name) {
    Job j;
    j.id = id;
    j.kind = kind;
    j.name = name;
    j.work_dir = "/spool/work/" + std::to_string(id);
    return j;
  }

  // Reserves an id and inserts a queued job with it.
  static int64_t add_job(Store& store, const std::string& kind = "knit",
                         const std::string& name = "cat.jpg") {
    int64_t id = store.reserve_id();
    store.insert_job(make_job(id, kind, name));
    return id;
  }

  // Shortest chain of allowed edges from queued to `target` (empty for queued itself).
  static std::vector<JobState> path_to(JobState target) {
    std::map<JobState, JobState> parent;
    std::deque<JobState> frontier = {S::queued};
    std::set<JobState> seen = {S::queued};
    while (!frontier.empty()) {
      JobState at = frontier.front();
      frontier.pop_front();
      for (const auto& [from, to] : kAllowed) {
        if (from == at && seen.insert(to).second) {
          parent[to] = at;
          frontier.push_back(to);
        }
      }
    }
    std::vector<JobState> path;
    for (JobState s = target; s != S::queued; s = parent.at(s)) path.push_back(s);
    std::reverse(path.begin(), path.end());
    return path;
  }

  static void drive_to(Store& store, int64_t id, JobState target) {
    for (JobState s : path_to(target)) store.transition(id, s, "on the way to " + state_name(target));
  }

  fs::path dir_;
};

}  // namespace atelier::test
