// The fixture of the line job tests, shared with the atelier-convert line and pencil-profile
// command tests: a scratch folder, parameters from --set lines, the ParamError a job throws.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "convert/common/param_table.h"
#include "convert/sketch/line_job.h"
#include "tests/e2e/daemon_harness.h"

namespace atelier::test {

namespace fs = std::filesystem;

class PencilLineJob : public ::testing::Test {
 protected:
  static toml::table params(const std::vector<std::string>& sets) {
    toml::table t;
    for (const auto& s : sets) apply_set(t, s);
    return t;
  }
  std::string param_error(const std::vector<std::string>& sets) {
    try {
      convert_line(params(sets), "--set", dir_ / "bad");
    } catch (const ParamError& e) {
      return e.what();
    }
    return "";
  }

  test::TempDir tmp_;
  const fs::path dir_ = tmp_.path();
};

}  // namespace atelier::test
