// The job-file kind probe (daemon/job_kind_probe.h): the kind of incoming/NAME.toml is read by
// an `atelier-convert --job-kind` child, whose crash, hang or memory use fails one job with a
// reason naming the file and never quoting it.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include "daemon/job_kind_probe.h"
#include "tests/e2e/daemon_harness.h"
#include "tests/support/fake_program.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

TEST(JobKindProbe, TheRealConverterNamesTheKindOfAJobFile) {
  test::TempDir tmp;
  test::write_file(tmp.path() / "eyelets.toml", "kind = \"lace\"\nwidth = 12\n");
  auto found = probe_job_kind(test::binary("atelier-convert"), tmp.path() / "eyelets.toml", "eyelets.toml");
  EXPECT_EQ(found.problem, "");
  EXPECT_EQ(found.kind, "lace");
}

TEST(JobKindProbe, AFileThatIsNotAJobFileFailsWithoutEchoingItsContent) {
  test::TempDir tmp;
  // A copy of /etc/passwd's shape, and TOML whose error quotes a key.
  test::write_file(tmp.path() / "passwd.toml", "root:x:0:0:root:/root:/bin/bash\ndaemon:x:1:1::/usr/sbin:/nologin\n");
  test::write_file(tmp.path() / "keys.toml", "kind = \"lace\"\nhunter2_secret = 1\nhunter2_secret = 2\n");
  test::write_file(tmp.path() / "kind.toml", "kind = \"root:x:0:0:root:/root\"\n");
  for (const char* name : {"passwd.toml", "keys.toml", "kind.toml"}) {
    auto found = probe_job_kind(test::binary("atelier-convert"), tmp.path() / name, name);
    EXPECT_EQ(found.kind, "") << name;
    EXPECT_EQ(found.problem.rfind(std::string(name) + ":", 0), 0u) << found.problem;
    for (const char* secret : {"root", "daemon", "nologin", "hunter2"})
      EXPECT_EQ(found.problem.find(secret), std::string::npos) << found.problem;
  }
}

TEST(JobKindProbe, ACrashOrAHangOfTheChildFailsTheJobFileNamingIt) {
  test::TempDir tmp;
  test::write_file(tmp.path() / "job.toml", "kind = \"lace\"\n");
  auto crashed = probe_job_kind(test::fake_program(tmp, "kill -SEGV $$"), tmp.path() / "job.toml", "job.toml");
  EXPECT_EQ(crashed.kind, "");
  EXPECT_EQ(crashed.problem.rfind("job.toml: ", 0), 0u) << crashed.problem;
  EXPECT_NE(crashed.problem.find("signal 11"), std::string::npos) << crashed.problem;

  JobKindProbeLimits limits;
  limits.timeout = 300ms;
  auto hung = probe_job_kind(test::fake_program(tmp, "exec sleep 30"), tmp.path() / "job.toml", "job.toml", limits);
  EXPECT_EQ(hung.kind, "");
  EXPECT_EQ(hung.problem.rfind("job.toml: ", 0), 0u) << hung.problem;
  EXPECT_NE(hung.problem.find("took longer"), std::string::npos) << hung.problem;

  // A parser caught in a loop: stopped by its CPU limit (CPU time, not wall time, so a busy
  // box does not fail good job files).
  JobKindProbeLimits cpu;
  cpu.cpu_seconds = 1;
  auto looping = probe_job_kind(test::fake_program(tmp, "while :; do :; done"), tmp.path() / "job.toml", "job.toml", cpu);
  EXPECT_EQ(looping.problem.rfind("job.toml: ", 0), 0u) << looping.problem;
  EXPECT_NE(looping.problem.find("CPU"), std::string::npos) << looping.problem;

  // Whatever else the child writes is not passed on.
  auto chatty = probe_job_kind(test::fake_program(tmp, "echo 'root:x:0:0' >&2; exit 1"), tmp.path() / "job.toml", "job.toml");
  EXPECT_EQ(chatty.problem.find("root"), std::string::npos) << chatty.problem;
}

TEST(JobKindProbe, TheChildRunsUnderTheMemoryLimit) {
  test::TempDir tmp;
  test::write_file(tmp.path() / "job.toml", "kind = \"lace\"\n");
  JobKindProbeLimits limits;
  limits.memory_bytes = 256ull << 20;
  // `ulimit -v` prints the address-space limit in KiB: the "kind" it reports.
  auto found = probe_job_kind(test::fake_program(tmp, "ulimit -v"), tmp.path() / "job.toml", "job.toml", limits);
  EXPECT_EQ(found.kind, std::to_string(256 * 1024));
}

}  // namespace
}  // namespace atelier
