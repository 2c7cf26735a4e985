// The child-process runner: a converter that fails, hangs, crashes or is canceled costs one
// job and is reported with a reason; progress lines reach the daemon.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>

#include "base/fake_clock.h"
#include "daemon/conversion_runner.h"
#include "tests/e2e/daemon_harness.h"

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using atelier::ConversionOutcome;
using atelier::ConversionTask;
using atelier::SubprocessRunner;

namespace {

// A stand-in converter: a shell script with the given body.
fs::path script(const fs::path& dir, const std::string& body) {
  fs::path p = dir / "fake-convert";
  std::ofstream(p) << "#!/bin/sh\n" << body << "\n";
  fs::permissions(p, fs::perms::owner_all);
  return p;
}

ConversionTask task(const fs::path& dir) {
  ConversionTask t;
  t.kind = "knit";
  t.input = dir / "in.png";
  t.output_dir = dir;
  t.defaults_toml = "width = 77\n";
  t.sets = {"solver=\"gsat\""};
  t.timeout = std::chrono::seconds(30);
  return t;
}

}  // namespace

TEST(ConversionRunner, PassesDefaultsOnStdinAndOverridesAsSetAndReportsProgress) {
  atelier::test::TempDir tmp;
  SubprocessRunner runner(script(tmp.path(),
                                 "cat > \"$3/stdin.txt\"; echo \"$@\" > \"$3/args.txt\"\n"
                                 "echo 'progress 0.25' >&3; echo 'progress 1.00' >&3; exit 0"));
  std::vector<double> seen;
  std::atomic<bool> cancel{false};
  auto out = runner.run(task(tmp.path()), [&](double f) { seen.push_back(f); }, cancel);
  EXPECT_EQ(out.status, ConversionOutcome::Status::ok) << out.message;
  EXPECT_EQ(seen, (std::vector<double>{0.25, 1.0}));
  std::ifstream stdin_copy(tmp.path() / "stdin.txt");
  std::string defaults((std::istreambuf_iterator<char>(stdin_copy)), {});
  EXPECT_EQ(defaults, "width = 77\n");
  std::ifstream args_file(tmp.path() / "args.txt");
  std::string args((std::istreambuf_iterator<char>(args_file)), {});
  EXPECT_NE(args.find("--params /dev/stdin"), std::string::npos) << args;
  EXPECT_NE(args.find("--set solver=\"gsat\""), std::string::npos) << args;
  EXPECT_NE(args.find("--max-pixels 40000000"), std::string::npos) << args;
  EXPECT_NE(args.find("--memory-mb 2048"), std::string::npos) << args;  // the default budget
}

TEST(ConversionRunner, AConverterKilledForMemoryNamesTheInputAndTheBudget) {
  atelier::test::TempDir tmp;
  // The kernel's OOM killer sends SIGKILL; the runner did not (no timeout, no cancel).
  SubprocessRunner runner(script(tmp.path(), "kill -KILL $$"), 512ull << 20);
  std::atomic<bool> cancel{false};
  auto out = runner.run(task(tmp.path()), nullptr, cancel);
  EXPECT_EQ(out.status, ConversionOutcome::Status::failed);
  EXPECT_EQ(out.message.rfind("in.png: needs more than 512 MB (limits.job_memory_mb)", 0), 0u) << out.message;
}

TEST(ConversionRunner, TheBudgetIsTheChildsAddressSpaceLimit) {
  atelier::test::TempDir tmp;
  SubprocessRunner runner(script(tmp.path(), "ulimit -v > \"$3/ulimit.txt\""), 300ull << 20);
  std::atomic<bool> cancel{false};
  auto out = runner.run(task(tmp.path()), nullptr, cancel);
  ASSERT_EQ(out.status, ConversionOutcome::Status::ok) << out.message;
  std::ifstream in(tmp.path() / "ulimit.txt");
  std::string kib;
  in >> kib;
  EXPECT_EQ(kib, std::to_string(300 * 1024));
}

TEST(ConversionRunner, AFailureCarriesTheConvertersMessageWithoutTheWorkPath) {
  atelier::test::TempDir tmp;
  SubprocessRunner runner(script(tmp.path(),
                                 "echo \"error: $3/in.png.toml:2: unknown key 'widht'\" >&2; exit 1"));
  std::atomic<bool> cancel{false};
  auto out = runner.run(task(tmp.path()), nullptr, cancel);
  EXPECT_EQ(out.status, ConversionOutcome::Status::failed);
  EXPECT_EQ(out.message, "in.png.toml:2: unknown key 'widht'");
}

TEST(ConversionRunner, ACrashIsAFailedJobNamingTheInput) {
  atelier::test::TempDir tmp;
  SubprocessRunner runner(script(tmp.path(), "kill -SEGV $$"));
  std::atomic<bool> cancel{false};
  auto out = runner.run(task(tmp.path()), nullptr, cancel);
  EXPECT_EQ(out.status, ConversionOutcome::Status::failed);
  EXPECT_NE(out.message.find("signal 11"), std::string::npos) << out.message;
  EXPECT_NE(out.message.find("in.png"), std::string::npos) << out.message;
}

TEST(ConversionRunner, AHungConverterIsKilledAtTheTimeout) {
  atelier::test::TempDir tmp;
  // The timeout is measured on the runner's clock: the converter reports progress once, the
  // clock is moved past the limit (ten minutes, which nobody waits for), and it hangs.
  atelier::FakeClock clock;
  SubprocessRunner runner(script(tmp.path(), "echo 'progress 0.10' >&3; exec sleep 60"), 8ull << 30, clock);
  auto t = task(tmp.path());
  t.timeout = std::chrono::seconds(600);
  std::atomic<bool> cancel{false};
  auto out = runner.run(t, [&](double) { clock.advance(601s); }, cancel);
  EXPECT_EQ(out.status, ConversionOutcome::Status::timed_out);
  EXPECT_NE(out.message.find("job_timeout_s"), std::string::npos) << out.message;
}

TEST(ConversionRunner, CancelStopsTheConverter) {
  atelier::test::TempDir tmp;
  SubprocessRunner runner(script(tmp.path(), "echo 'progress 0.10' >&3; exec sleep 60"));
  std::atomic<bool> cancel{false};
  auto out = runner.run(task(tmp.path()), [&](double) { cancel = true; }, cancel);
  EXPECT_EQ(out.status, ConversionOutcome::Status::canceled);
}
