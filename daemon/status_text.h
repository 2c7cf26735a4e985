// The daemon's one-line status for systemd (sd_notify STATUS=, shown by `systemctl status
// atelierd`): how many jobs are in each state, e.g.
//   "3 queued, 1 converting, 2 ready, 1 running, 40 completed, 2 failed"
// The six states of the main flow always appear (zero included); canceled and interrupted
// jobs only when there are some ("..., 1 interrupted"), since an interrupted job waits for
// an operator. Pure.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "daemon/store.h"

namespace atelier {

// `counts`: jobs per state (Store::counts()); a missing state counts as zero.
std::string status_text(const std::map<JobState, int64_t>& counts);

}  // namespace atelier
