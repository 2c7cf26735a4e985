// Every installed program answers --version with "PROGRAM VERSION" (project(VERSION) in the
// top CMakeLists.txt, compiled in as ATELIER_VERSION) on stdout and exits 0, as an operator
// checking what is installed expects; a mistyped option exits 2. Runs the built programs.
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace {

namespace fs = std::filesystem;

struct VersionRun {
  int exit_code = -1;
  std::string out;
};

VersionRun run_with(const fs::path& program, const std::string& arg) {
  VersionRun r;
  const std::string command = "'" + program.string() + "' " + arg + " 2>/dev/null </dev/null";
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return r;
  char buf[256];
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;) r.out.append(buf, n);
  const int status = ::pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return r;
}

class VersionFlag : public ::testing::TestWithParam<const char*> {};

TEST_P(VersionFlag, PrintsProgramAndVersionAndExitsZero) {
  const fs::path program = fs::path(ATELIER_BINARY_DIR) / "bin" / GetParam();
  ASSERT_TRUE(fs::exists(program)) << program << " is not built";
  const VersionRun r = run_with(program, "--version");
  EXPECT_EQ(r.exit_code, 0) << program;
  EXPECT_EQ(r.out, std::string(GetParam()) + " " + ATELIER_VERSION + "\n") << program;
}

// A mistyped option is a usage error with the same exit status everywhere (2, as getopt
// programs and CUPS's tools use), so scripts and the man pages can rely on it.
TEST_P(VersionFlag, AnUnknownOptionIsAUsageErrorExitingTwo) {
  const fs::path program = fs::path(ATELIER_BINARY_DIR) / "bin" / GetParam();
  ASSERT_TRUE(fs::exists(program)) << program << " is not built";
  EXPECT_EQ(run_with(program, "--no-such-option").exit_code, 2) << program;
}

INSTANTIATE_TEST_SUITE_P(InstalledPrograms, VersionFlag,
                         ::testing::Values("atelierd", "atelierctl", "atelier-convert",
                                           "atelier-knit-emu", "atelier-laser-emu"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (c == '-') c = '_';
                           return name;
                         });

}  // namespace
