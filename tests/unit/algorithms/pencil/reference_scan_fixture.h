// Test helper shared by the reference-scan and pencil-profile-file tests: a grade model by name.
#pragma once

#include <stdexcept>
#include <string>

#include "algorithms/pencil/reference_scan.h"

namespace atelier::pencil::testing {

inline const pencil::GradeModel& model(const std::string& name) {
  const pencil::GradeModel* m = pencil::find_grade_model(name);
  if (!m) throw std::logic_error("no grade model " + name);
  return *m;
}

}  // namespace atelier::pencil::testing
