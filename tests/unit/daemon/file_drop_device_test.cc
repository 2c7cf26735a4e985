// The file-drop driver: a converted embroidery job's stitch files reach the machine's folder
// whole, and a missing or full folder fails the job with its reason, loses nothing and leaves no
// half job behind.
#include <gtest/gtest.h>

#include <cerrno>
#include <fstream>
#include <set>

#include "base/fake_clock.h"
#include "daemon/file_drop_device.h"
#include "daemon/job_service.h"
#include "tests/e2e/daemon_harness.h"
#include "tests/support/job_watch.h"

namespace fs = std::filesystem;
using atelier::DeviceConfig;
using atelier::DropError;
using atelier::DropFolder;
using atelier::FileDropDevice;
using atelier::JobService;
using atelier::JobState;
using atelier::SpoolLayout;
using atelier::Store;

namespace {

std::string slurp(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// A spool with one converted embroidery job, ready for the device.
struct ReadyJob {
  atelier::test::TempDir tmp;
  SpoolLayout layout{tmp.path() / "spool"};
  Store store{tmp.path() / "jobs.sqlite"};
  atelier::FakeClock clock;  // the worker's idle waits: nothing here moves it
  atelier::test::JobWatch watch{clock};
  JobService jobs{store, layout, watch.listener()};
  int64_t id = 0;

  ReadyJob() {
    jobs.ensure_layout();
    atelier::test::write_file(layout.incoming("embroidery") / "my cat.png", "png bytes");
    id = *jobs.claim(layout.incoming("embroidery") / "my cat.png");
    jobs.transition(id, JobState::converting, "converting");
    atelier::test::write_file(layout.work(id) / "design.dst", std::string(515, 'D'));
    atelier::test::write_file(layout.work(id) / "design.exp", std::string(40, 'E'));
    atelier::test::write_file(layout.work(id) / "design.pes", std::string(700, 'P'));
    atelier::test::write_file(layout.work(id) / "design.jef", std::string(130, 'J'));
    jobs.finish_converted(id, JobState::ready, "converted; waiting for emb");
  }

  DeviceConfig device(const fs::path& dir) const {
    DeviceConfig d;
    d.name = "emb";
    d.driver = "file-drop";
    d.dir = dir.string();
    d.kinds = {"embroidery"};
    d.formats = {"dst", "exp"};
    d.autostart = true;
    return d;
  }

  // Runs the device until it is done with the job (it leaves running).
  atelier::Job run(FileDropDevice& device) {
    device.start_worker();
    device.wake();
    EXPECT_TRUE(watch.wait_left(id, JobState::running));
    return *store.get(id);
  }
};

// A stick that fills up after `room` files.
class FullStick : public DropFolder {
 public:
  explicit FullStick(int room, std::set<std::string>& files) : room_(room), files_(files) {}
  bool present() const override { return true; }
  void write_atomically(const std::string& name, std::string_view) override {
    if (static_cast<int>(files_.size()) >= room_)
      throw DropError("/media/EMB: No space left on device writing " + name, ENOSPC);
    files_.insert(name);
  }
  void remove(const std::string& name) noexcept override { files_.erase(name); }

 private:
  int room_;
  std::set<std::string>& files_;
};

}  // namespace

TEST(FileDropDevice, WritesEveryFormatUnderTheJobsNameAndCompletesTheJob) {
  ReadyJob r;
  const fs::path stick = r.tmp.path() / "EMB";
  fs::create_directories(stick);
  FileDropDevice device(r.device(stick), r.jobs, nullptr, r.clock);
  const atelier::Job job = r.run(device);
  ASSERT_EQ(job.state, JobState::completed) << job.reason;
  const std::string dst = std::to_string(r.id) + "-my_cat.dst";
  const std::string exp = std::to_string(r.id) + "-my_cat.exp";
  EXPECT_EQ(slurp(stick / dst), std::string(515, 'D'));
  EXPECT_EQ(slurp(stick / exp), std::string(40, 'E'));
  EXPECT_NE(job.reason.find(dst), std::string::npos) << job.reason;
  int entries = 0;
  for (const auto& e : fs::directory_iterator(stick)) entries += e.exists() ? 1 : 0;
  EXPECT_EQ(entries, 2) << "no temporary file may be left on the stick";
}

TEST(FileDropDevice, AHomeMachinesDeviceWritesExactlyItsFormats) {
  ReadyJob r;
  const fs::path stick = r.tmp.path() / "EMB";
  fs::create_directories(stick);
  DeviceConfig config = r.device(stick);
  config.formats = {"pes", "jef"};
  FileDropDevice device(config, r.jobs, nullptr, r.clock);
  const atelier::Job job = r.run(device);
  ASSERT_EQ(job.state, JobState::completed) << job.reason;
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(stick)) names.insert(e.path().filename().string());
  const std::string stem = std::to_string(r.id) + "-my_cat";
  EXPECT_EQ(names, (std::set<std::string>{stem + ".pes", stem + ".jef"}));
  EXPECT_EQ(slurp(stick / (stem + ".pes")), std::string(700, 'P'));
  EXPECT_EQ(slurp(stick / (stem + ".jef")), std::string(130, 'J'));
}

TEST(FileDropDevice, AMissingFolderFailsTheJobWithItsReasonAndKeepsTheDesign) {
  ReadyJob r;
  FileDropDevice device(r.device(r.tmp.path() / "not-mounted"), r.jobs, nullptr, r.clock);
  const atelier::Job job = r.run(device);
  ASSERT_EQ(job.state, JobState::failed);
  EXPECT_NE(job.reason.find("not-mounted is missing"), std::string::npos) << job.reason;
  EXPECT_NE(job.reason.find("retry"), std::string::npos) << job.reason;
  EXPECT_EQ(slurp(fs::path(job.output_dir) / "design.dst"), std::string(515, 'D'));
}

TEST(FileDropDevice, AFullStickFailsTheJobAndTakesBackWhatItHadWritten) {
  ReadyJob r;
  std::set<std::string> files;
  FileDropDevice device(r.device("/media/EMB"), r.jobs,
                        [&](const fs::path&) { return std::make_unique<FullStick>(1, files); }, r.clock);
  const atelier::Job job = r.run(device);
  ASSERT_EQ(job.state, JobState::failed);
  EXPECT_NE(job.reason.find("No space left"), std::string::npos) << job.reason;
  EXPECT_TRUE(files.empty()) << "the .dst written before the stick filled up must be removed";
  EXPECT_EQ(slurp(fs::path(job.output_dir) / "design.exp"), std::string(40, 'E'));
}

TEST(FileDropDevice, TheRealFolderWriterReportsAMissingFolderAndLeavesNoPartFile) {
  atelier::test::TempDir tmp;
  atelier::PosixDropFolder gone(tmp.path() / "gone");
  try {
    gone.write_atomically("1-x.dst", "abc");
    FAIL() << "writing into a missing folder must throw";
  } catch (const DropError& e) {
    EXPECT_EQ(e.error_number(), ENOENT);
    EXPECT_NE(std::string(e.what()).find("gone"), std::string::npos) << e.what();
  }
  atelier::PosixDropFolder here(tmp.path());
  here.write_atomically("1-x.dst", "abc");
  EXPECT_EQ(slurp(tmp.path() / "1-x.dst"), "abc");
  EXPECT_FALSE(fs::exists(tmp.path() / ".1-x.dst.part"));
  // A file of the same name (another store's job 1, say) is never replaced.
  try {
    here.write_atomically("1-x.dst", "other design");
    FAIL() << "an existing file must not be replaced";
  } catch (const DropError& e) {
    EXPECT_EQ(e.error_number(), EEXIST) << e.what();
  }
  EXPECT_EQ(slurp(tmp.path() / "1-x.dst"), "abc");
  EXPECT_FALSE(fs::exists(tmp.path() / ".1-x.dst.part"));
}
