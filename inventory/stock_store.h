// The workshop's stock of used wood on disk, so that no piece of veneer is planned twice.
//
// <dir>/stock.json = {"version": 1, "sheets": {"<sheet id>": [{"job": "12", "piece": 3,
//                     "polygon": [[x, y], ...]}, ...]}}
// Polygons are in sheet mm (origin at the scan's top-left, x right, y down; see
// algorithms/parquetry/sheet.h), closed, first point not repeated.
//
// Errors: ConvertError naming the file. Concurrency: load/save are plain file operations; a
// StockLock held across load -> plan -> write outputs -> save serialises conversions (and
// the daemon's `wood` verbs) across threads and processes.
#pragma once

#include <filesystem>

#include "algorithms/parquetry/sheet.h"
#include "convert/common/convert_error.h"

namespace atelier {

// A missing file (or folder) is an empty stock. ConvertError on a corrupt file (names it).
parquetry::Stock load_stock(const std::filesystem::path& dir);

// Writes <dir>/stock.json atomically (temporary file + rename); creates dir when `create`
// (otherwise a missing dir is a ConvertError naming it).
void save_stock(const std::filesystem::path& dir, const parquetry::Stock& stock, bool create = true);

// Exclusive advisory lock (flock) on <dir>/stock.lock for the object's lifetime; the
// constructor blocks until it holds the lock and creates dir. ConvertError if the lock file
// cannot be opened. Also excludes other threads of the same process (each object opens its
// own descriptor). Non-copyable, non-movable.
class StockLock {
 public:
  // `create`: make dir if missing (atelier-convert run by hand); false: a missing dir is a
  // ConvertError "DIR: no such stock folder" (a conversion run by the daemon).
  explicit StockLock(const std::filesystem::path& dir, bool create = true);
  ~StockLock();
  StockLock(const StockLock&) = delete;
  StockLock& operator=(const StockLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace atelier
