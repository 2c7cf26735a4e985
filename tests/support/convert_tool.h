// Runs the built atelier-convert program in a test's own temporary folder: exit code and
// stderr, as the daemon and users see them.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace atelier::test {

class ConvertToolFixture : public ::testing::Test {
 public:
  static std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  static void write(const std::filesystem::path& p, const std::string& text) {
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
  }

 protected:
  void SetUp() override {
    ASSERT_TRUE(std::filesystem::exists(tool_path())) << tool_path() << " is not built";
    // Short: reasons name paths under it, and a test checks their length (in the daemon they
    // are relative to the job's folder).
    static int count = 0;
    dir_ = std::filesystem::temp_directory_path() /
           ("ac-" + std::to_string(::getpid()) + "-" + std::to_string(++count));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // The build's atelier-convert; $ATELIER_TEST_CONVERT_TOOL runs the tests on another one
  // (e.g. a wrapper around an older build, to see which of them it fails).
  static std::filesystem::path tool_path() {
    if (const char* other = std::getenv("ATELIER_TEST_CONVERT_TOOL"); other && *other) return other;
    return std::filesystem::path(ATELIER_BINARY_DIR) / "bin" / "atelier-convert";
  }
  // Single-quoted for the shell (names may hold any byte but NUL).
  static std::string q(const std::string& s) {
    std::string out = "'";
    for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
  }
  static std::string q(const std::filesystem::path& p) { return q(p.string()); }

  // Runs the tool with `args` (already quoted); returns the exit code, stderr in err().
  int tool(const std::string& args) {
    const std::string cmd = q(tool_path()) + " " + args + " >/dev/null 2>" + q(dir_ / "stderr.txt");
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  // stderr of the last run without the "error: " prefix and the final newline.
  std::string err() {
    std::string e = slurp(dir_ / "stderr.txt");
    if (e.rfind("error: ", 0) == 0) e.erase(0, 7);
    while (!e.empty() && e.back() == '\n') e.pop_back();
    return e;
  }

  std::filesystem::path dir_;
};

}  // namespace atelier::test
