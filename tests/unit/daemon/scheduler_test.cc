// Parquetry jobs queued together are planned together (paper 4.2): one conversion with a
// `--with` target per extra job, all moving through converting -> ready (or failed) at once;
// jobs with other overrides, or of other kinds, are converted on their own. A canceled batch
// job ends canceled and the others are converted again; a stopped batch is re-queued whole.
#include <gtest/gtest.h>

#include <set>

#include <condition_variable>
#include <fstream>
#include <mutex>
#include <thread>

#include "base/fake_clock.h"
#include "daemon/scheduler.h"
#include "tests/e2e/daemon_harness.h"
#include "tests/support/job_watch.h"

namespace fs = std::filesystem;
using namespace atelier;

namespace {

// Records every task; each run waits until released (or canceled), then ends as scripted.
// Like a real runner it looks at its cancel flag every so often (every 10 ms of the test's
// FakeClock); tick() lets it take its next look.
class FakeRunner : public ConversionRunner {
 public:
  explicit FakeRunner(FakeClock& clock) : clock_(clock) {}

  ConversionOutcome run(const ConversionTask& task, const std::function<void(double)>& progress,
                        const std::atomic<bool>& cancel) override {
    progress(0.5);  // before the task shows: a test that sees the task sees the progress
    std::unique_lock lock(mu_);
    tasks_.push_back(task);
    ++running_;
    cv_.notify_all();
    while (!released_ && !cancel.load()) {
      ++looks_;
      waiting_ = true;
      cv_.notify_all();
      clock_.wait_for(cv_, lock, std::chrono::milliseconds(10), [&] { return released_; });
      waiting_ = false;
    }
    --running_;
    cv_.notify_all();
    if (cancel.load() && !released_) return {ConversionOutcome::Status::canceled, "canceled"};
    bool bad = fail_ || bad_dirs_.count(task.output_dir);
    for (const auto& [input, output] : task.together) bad = bad || bad_dirs_.count(output);
    if (bad) return {ConversionOutcome::Status::failed, "wood.png: out of wood: needs 900 mm^2"};
    for (const auto& [input, output] : task.together) std::ofstream(output / "plan.json") << "{}";
    std::ofstream(task.output_dir / "plan.json") << "{}";
    if (!report_.empty()) std::ofstream(task.output_dir / "report.json") << report_;
    return {ConversionOutcome::Status::ok, ""};
  }
  // Until `n` tasks have been seen and one is under way.
  bool wait_tasks(size_t n) {
    std::unique_lock lock(mu_);
    cv_.wait(lock, [&] { return tasks_.size() >= n && running_ > 0; });
    return true;
  }
  // Lets the conversion under way look at its cancel flag once more: waits until it waits for
  // its next look, then moves the clock there. False once no conversion is under way.
  bool tick() {
    std::unique_lock lock(mu_);
    cv_.wait(lock, [&] { return running_ == 0 || (waiting_ && looks_ != ticked_); });
    if (running_ == 0) return false;
    ticked_ = looks_;
    lock.unlock();
    clock_.advance(std::chrono::milliseconds(10));
    return true;
  }
  void release(bool fail = false) {
    {
      std::lock_guard lock(mu_);
      released_ = true;
      fail_ = fail;
    }
    cv_.notify_all();
  }
  // Any conversion that includes the job writing to `dir` fails (a bad input in a batch).
  void fail_output(const std::filesystem::path& dir) {
    std::lock_guard lock(mu_);
    bad_dirs_.insert(dir);
  }
  // report.json each conversion writes (none when empty).
  void write_report(const std::string& json) {
    std::lock_guard lock(mu_);
    report_ = json;
  }
  std::vector<ConversionTask> tasks() {
    std::lock_guard lock(mu_);
    return tasks_;
  }

 private:
  FakeClock& clock_;
  std::mutex mu_;
  std::condition_variable_any cv_;
  std::vector<ConversionTask> tasks_;
  int running_ = 0;
  bool waiting_ = false;            // a run waits for its next look at the cancel flag
  uint64_t looks_ = 0, ticked_ = 0;  // waits begun; the last one tick() moved the clock for
  bool released_ = false, fail_ = false;
  std::set<std::filesystem::path> bad_dirs_;
  std::string report_;
};

struct Rig {
  test::TempDir tmp;
  SpoolLayout layout{tmp.path() / "spool"};
  Store store{tmp.path() / "jobs.sqlite"};
  FakeClock clock;  // the runner's looks at its cancel flag
  test::JobWatch watch{clock};
  JobService jobs{store, layout, watch.listener()};
  FakeRunner runner{clock};
  std::shared_ptr<const Config> config;
  Scheduler scheduler{jobs, runner, [this] { return config; }};

  Rig() {
    jobs.ensure_layout();
    config = std::make_shared<const Config>(parse_config("[spool]\ndir = \"/x\"\n", "t.toml"));
    scheduler.set_device_hooks([](const Job& j) { return j.kind == "parquetry" ? std::string("laser") : ""; },
                               nullptr);
  }
  int64_t drop(const std::string& kind, const std::string& name, const std::string& sidecar = "") {
    if (!sidecar.empty()) test::write_file(layout.incoming(kind) / (name + ".toml"), sidecar);
    test::write_file(layout.incoming(kind) / name, "image " + name);
    const int64_t id = *jobs.claim(layout.incoming(kind) / name);
    scheduler.enqueue(id);
    return id;
  }
  JobState state(int64_t id) { return store.get(id)->state; }
  // Until job `id` is in `s`, or has settled in another state (ready, completed, failed,
  // canceled: the scheduler is done with it). Whether it is in `s`.
  bool wait_state(int64_t id, JobState s) {
    const auto settled = {s, JobState::ready, JobState::completed, JobState::failed, JobState::canceled};
    return watch.wait_state_in(id, settled) == s;
  }
};

TEST(SchedulerBatch, QueuedParquetryJobsArePlannedInOneConversion) {
  Rig rig;
  const int64_t a = rig.drop("parquetry", "a.jpg");
  const int64_t b = rig.drop("parquetry", "b.jpg");
  const int64_t knit = rig.drop("knit", "k.png");
  const int64_t c = rig.drop("parquetry", "c.jpg");
  const int64_t other = rig.drop("parquetry", "d.jpg", "size_mm = 100\n");  // own overrides
  rig.scheduler.start(1);
  ASSERT_TRUE(rig.runner.wait_tasks(1));
  // a, b and c convert together; the knit job and d (other overrides) wait their turn.
  EXPECT_EQ(rig.state(a), JobState::converting);
  EXPECT_EQ(rig.state(b), JobState::converting);
  EXPECT_EQ(rig.state(c), JobState::converting);
  EXPECT_EQ(rig.state(knit), JobState::queued);
  EXPECT_EQ(rig.state(other), JobState::queued);
  auto task = rig.runner.tasks().front();
  EXPECT_EQ(task.job_id, a);
  ASSERT_EQ(task.together.size(), 2u);
  EXPECT_EQ(task.together[0].first, rig.layout.work(b) / "b.jpg");
  EXPECT_EQ(task.together[0].second, rig.layout.work(b));
  EXPECT_EQ(task.together[1].second, rig.layout.work(c));
  EXPECT_EQ(task.timeout, std::chrono::seconds(600 * 3));
  EXPECT_EQ(rig.store.get(b)->progress_done, 50);  // progress reaches every job of the batch

  rig.runner.release();
  for (int64_t id : {a, b, c}) {
    ASSERT_TRUE(rig.wait_state(id, JobState::ready)) << id;
    EXPECT_TRUE(fs::exists(rig.layout.done(id) / "plan.json")) << id;  // each its own outputs
  }
  ASSERT_TRUE(rig.wait_state(other, JobState::ready));
  ASSERT_TRUE(rig.wait_state(knit, JobState::completed));
  const auto tasks = rig.runner.tasks();
  ASSERT_EQ(tasks.size(), 3u);
  for (size_t i = 1; i < tasks.size(); ++i) EXPECT_TRUE(tasks[i].together.empty());
  rig.scheduler.stop();
}

TEST(SchedulerBatch, AFailedBatchConvertsEachJobAloneSoOnlyTheBadOneFails) {
  Rig rig;
  const int64_t a = rig.drop("parquetry", "a.jpg");
  const int64_t b = rig.drop("parquetry", "b.jpg");
  rig.runner.fail_output(rig.layout.work(a));
  rig.scheduler.start(1);
  rig.runner.release();
  ASSERT_TRUE(rig.wait_state(a, JobState::failed));
  EXPECT_EQ(rig.store.get(a)->reason, "wood.png: out of wood: needs 900 mm^2");
  EXPECT_TRUE(fs::exists(rig.layout.failed(a) / "a.jpg"));
  ASSERT_TRUE(rig.wait_state(b, JobState::ready)) << rig.store.get(b)->reason;
  const auto tasks = rig.runner.tasks();
  ASSERT_EQ(tasks.size(), 3u);  // together, then each alone
  EXPECT_EQ(tasks[0].together.size(), 1u);
  EXPECT_EQ(tasks[1].job_id, a);
  EXPECT_TRUE(tasks[1].together.empty());
  EXPECT_EQ(tasks[2].job_id, b);
  EXPECT_TRUE(tasks[2].together.empty());
  rig.scheduler.stop();
}

TEST(SchedulerBatch, CancelingOneJobConvertsTheOthersAgain) {
  Rig rig;
  const int64_t a = rig.drop("parquetry", "a.jpg");
  const int64_t b = rig.drop("parquetry", "b.jpg");
  rig.scheduler.start(1);
  ASSERT_TRUE(rig.runner.wait_tasks(1));
  ASSERT_TRUE(rig.scheduler.cancel(b));
  ASSERT_TRUE(rig.runner.tick());  // the conversion sees its flag
  ASSERT_TRUE(rig.wait_state(b, JobState::canceled));
  ASSERT_TRUE(rig.runner.wait_tasks(2));  // a alone, at once
  EXPECT_EQ(rig.runner.tasks()[1].job_id, a);
  EXPECT_TRUE(rig.runner.tasks()[1].together.empty());
  rig.runner.release();
  EXPECT_TRUE(rig.wait_state(a, JobState::ready));
  rig.scheduler.stop();
}

TEST(SchedulerBatch, AStoppedBatchIsQueuedAgainWholeAndRecovered) {
  Rig rig;
  const int64_t a = rig.drop("parquetry", "a.jpg");
  const int64_t b = rig.drop("parquetry", "b.jpg");
  rig.scheduler.start(1);
  ASSERT_TRUE(rig.runner.wait_tasks(1));
  // stop() sets the conversion's cancel flag first, then waits for it to end: let the
  // conversion look at its flag until it has seen it.
  std::thread stopper([&] { rig.scheduler.stop(); });
  while (rig.runner.tick()) {
  }
  stopper.join();
  EXPECT_EQ(rig.state(a), JobState::queued);
  EXPECT_EQ(rig.state(b), JobState::queued);
  EXPECT_EQ(rig.jobs.recover(), (std::vector<int64_t>{a, b}));
}

}  // namespace

// A conversion's report.json warnings reach the job's reason when it is done,
// before anyone carries the job to a machine.
TEST(SchedulerWarnings, TheReportsWarningsAreInTheConvertedJobsReason) {
  Rig rig;
  rig.runner.write_report(
      R"({"kind":"knit","knittable":false,"warnings":["not knittable as is: floats up to 14 needles, limit 4","second"]})");
  const int64_t knit = rig.drop("knit", "k.png");
  rig.scheduler.start(1);
  ASSERT_TRUE(rig.runner.wait_tasks(1));
  rig.runner.release();
  ASSERT_TRUE(rig.wait_state(knit, JobState::completed));
  EXPECT_EQ(rig.store.get(knit)->reason,
            "converted; no device for kind knit; warning: not knittable as is: floats up to 14 needles, limit 4 "
            "(and 1 more: atelierctl show)");
  rig.scheduler.stop();
}
