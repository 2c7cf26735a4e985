// The names of the job states, in lifecycle order (DESIGN.md "Job states"): the one list
// that the store (daemon/store.h, enum JobState in the same order), the control protocol and
// atelierctl (its --state check and the status counts) all read. Header-only, constants;
// any thread.
#pragma once

#include <array>
#include <string>
#include <string_view>

namespace atelier {

inline constexpr std::array<std::string_view, 8> kJobStateNames = {
    "queued", "converting", "ready", "running", "completed", "failed", "canceled", "interrupted"};

// "queued, converting, ready, ..." for messages.
inline std::string job_state_list_text() {
  std::string out;
  for (std::string_view s : kJobStateNames) {
    if (!out.empty()) out += ", ";
    out += s;
  }
  return out;
}

}  // namespace atelier
