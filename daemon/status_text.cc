#include "daemon/status_text.h"

namespace atelier {

std::string status_text(const std::map<JobState, int64_t>& counts) {
  auto count = [&](JobState s) {
    auto it = counts.find(s);
    return it == counts.end() ? int64_t{0} : it->second;
  };
  std::string out;
  auto add = [&](JobState s) {
    out += (out.empty() ? "" : ", ") + std::to_string(count(s)) + " " + state_name(s);
  };
  for (JobState s : {JobState::queued, JobState::converting, JobState::ready, JobState::running,
                     JobState::completed, JobState::failed})
    add(s);
  for (JobState s : {JobState::canceled, JobState::interrupted})
    if (count(s) > 0) add(s);
  return out;
}

}  // namespace atelier
