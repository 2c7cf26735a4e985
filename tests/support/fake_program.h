// A stand-in for a program the daemon runs as a child (atelier-convert): a shell script with
// `body`, written into the test's temporary folder and made executable. Returns its path.
#pragma once

#include <filesystem>
#include <string>

#include "tests/e2e/daemon_harness.h"

namespace atelier::test {

inline std::filesystem::path fake_program(const TempDir& tmp, const std::string& body) {
  const std::filesystem::path exe = tmp.path() / "fake-convert";
  write_file(exe, "#!/bin/sh\n" + body + "\n");
  std::filesystem::permissions(exe, std::filesystem::perms::owner_all);
  return exe;
}

}  // namespace atelier::test
