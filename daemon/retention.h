// Retention: which finished jobs to purge ([store] keep_days, keep_jobs). Pure: no store, no
// files, no clock (the caller passes the time); daemon/purge.h does the purging.
//
// Units: days of 24 hours; times are milliseconds since the Unix epoch (UTC), as in the store.
// Threading: plain functions of their arguments.
#pragma once

#include <cstdint>
#include <vector>

#include "daemon/store.h"

namespace atelier {

struct RetentionPolicy {
  // A finished job whose last change is more than this many days old is purged; 0 = never.
  int keep_days = 30;
  // At most this many finished jobs are kept, the most recently finished; 0 = no limit.
  int keep_jobs = 500;
};

// The jobs of `finished` (only finished jobs: Store::finished_jobs()) that `policy` purges at
// `now_ms`: every one finished more than keep_days before now_ms, and every one beyond the
// keep_jobs most recently finished (equal times: the higher id counts as the newer). Ids in
// ascending order.
std::vector<int64_t> jobs_to_purge(std::vector<FinishedJob> finished, const RetentionPolicy& policy,
                                   int64_t now_ms);

}  // namespace atelier
