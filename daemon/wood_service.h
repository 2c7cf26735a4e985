// The daemon's `wood` control verb: the workshop's veneer library (a wood folder, see
// inventory/wood_library.h) and its stock of used wood (stock.json, stock_store.h).
//
//   list                  every sheet: id, image, dpi, size_mm, usable/used/free mm^2, used %,
//                         pieces, jobs using it
//   add {id,image,dpi,mask?}  copies a scan into the wood folder (read from the client's open
//                         file: WoodScans)
//   remove {id, force?}   refused while the stock has pieces on the sheet, unless force
//   reset {id?, job?}     forgets used wood: of one sheet, of one job, of one job on one
//                         sheet, or all
//
// Where: the parquetry kind's `wood` and `stock` defaults (config.cc injects
// <state>/wood and <state>/wood-stock). add/remove write the configured wood folder; when
// `wood` is a list of sheets they are refused (edit the config instead).
// Stock changes take the StockLock of stock_store.h; a conversion holds it while it plans, so
// the verb waits at most `lock_wait` and then answers that the stock is busy (the control
// socket serves one request at a time and must not stall behind a long plan).
//
// Errors: WoodError with the message for the operator. Threading: stateless functions; the
// lock makes concurrent use with conversions safe.
#pragma once

#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <toml++/toml.h>

#include "base/error.h"
#include "base/unique_fd.h"
#include "convert/common/image_input.h"

namespace atelier {

class WoodError : public BadInput {
 public:
  using BadInput::BadInput;
};

// The open files of a `wood add` (client_file.h: opened by the client, with its rights).
struct WoodScans {
  UniqueFd image;
  UniqueFd mask;  // invalid: no mask
};

struct WoodPlaces {
  toml::table parquetry;                        // the kind's defaults (wood, dpi, stock, ...)
  std::string source = "config";                // for messages about them
  std::optional<std::filesystem::path> stock;   // none: stock not kept (verb refused)
  ImageLimits limits;
  std::chrono::milliseconds lock_wait{3000};
  std::string busy_hint;                        // e.g. "job 7 is being planned" (may be "")
  // A folder of the daemon's own where `add` copies the scans it is handed before checking
  // and adding them (created if missing; emptied of them afterwards).
  std::filesystem::path staging;
};

// Runs one request ({"action": "list"|"add"|"remove"|"reset", ...}); returns its answer.
// list: {"wood": folder or "list", "stock": dir, "sheets": [...]}; the others: {"done": text,
// "sheets": <list after the change>}. `add` reads the scan (and mask) from `scans`, never from
// the paths in `args`, which only name them; a scan larger than places.limits.max_file_bytes
// or not a regular file is refused.
nlohmann::json wood_request(const WoodPlaces& places, const nlohmann::json& args, WoodScans scans = {});

}  // namespace atelier
