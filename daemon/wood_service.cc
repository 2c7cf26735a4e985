#include "daemon/wood_service.h"

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <set>
#include <thread>

#include <opencv2/core.hpp>

#include "convert/common/param_table.h"
#include "convert/parquetry/parquetry_params.h"
#include "daemon/client_file.h"
#include "inventory/stock_store.h"
#include "inventory/wood_library.h"

namespace fs = std::filesystem;

namespace atelier {
namespace {

// Resolution of the area figures: 2 px/mm puts a pixel's error at 0.25 mm^2.
constexpr double kAreaPxPerMm = 2.0;

// The StockLock taken on a helper thread, so the caller can give up after a while: if it
// does, the thread releases the lock as soon as it gets it.
class TimedStockLock {
 public:
  TimedStockLock(const fs::path& dir, std::chrono::milliseconds wait) : state_(std::make_shared<State>()) {
    std::thread([state = state_, dir] {
      std::unique_ptr<StockLock> lock;
      std::exception_ptr error;
      try {
        lock = std::make_unique<StockLock>(dir);
      } catch (...) {
        error = std::current_exception();
      }
      std::lock_guard guard(state->mu);
      if (!state->abandoned) {
        state->lock = std::move(lock);
        state->error = error;
        state->done = true;
      }
      state->cv.notify_all();
    }).detach();
    std::unique_lock guard(state_->mu);
    if (!state_->cv.wait_for(guard, wait, [&] { return state_->done; })) {
      state_->abandoned = true;
      return;
    }
    if (state_->error) std::rethrow_exception(state_->error);
  }
  bool held() const {
    std::lock_guard guard(state_->mu);
    return state_->lock != nullptr;
  }

 private:
  struct State {
    mutable std::mutex mu;
    std::condition_variable cv;
    bool done = false, abandoned = false;
    std::unique_ptr<StockLock> lock;
    std::exception_ptr error;
  };
  std::shared_ptr<State> state_;
};

struct Wood {
  ParquetryParams params;
  std::vector<SheetEntry> entries;
};

Wood read_wood(const WoodPlaces& places) {
  Wood w;
  try {
    w.params = read_parquetry_params(places.parquetry, places.source);
    w.entries = require_wood(w.params, places.source);
  } catch (const std::exception& e) {
    throw WoodError(e.what());
  }
  return w;
}

nlohmann::json sheets_json(const WoodPlaces& places, const Wood& wood, const parquetry::Stock& stock) {
  std::vector<parquetry::Sheet> sheets;
  try {
    sheets = load_sheets(wood.entries, places.limits);
  } catch (const std::exception& e) {
    throw WoodError(e.what());
  }
  nlohmann::json out = nlohmann::json::array();
  for (size_t i = 0; i < sheets.size(); ++i) {
    const parquetry::Sheet& s = sheets[i];
    const auto it = stock.used.find(s.id);
    static const std::vector<parquetry::UsedPiece> kNone;
    const auto& pieces = it == stock.used.end() ? kNone : it->second;
    const double px_area = 1.0 / (kAreaPxPerMm * kAreaPxPerMm);
    const double usable = cv::countNonZero(parquetry::usable_mask(s, kAreaPxPerMm)) * px_area;
    const double used = parquetry::used_area_mm2(pieces);
    const double free = parquetry::free_area_mm2({s}, stock, kAreaPxPerMm);
    std::set<std::string> jobs;
    for (const auto& p : pieces) jobs.insert(p.job);
    const double mm_per_px = 25.4 / s.dpi;
    out.push_back({{"id", s.id},
                   {"image", wood.entries[i].image.string()},
                   {"mask", wood.entries[i].mask.string()},
                   {"dpi", s.dpi},
                   {"size_mm", {s.image.cols * mm_per_px, s.image.rows * mm_per_px}},
                   {"usable_mm2", usable},
                   {"used_mm2", used},
                   {"free_mm2", free},
                   {"used_pct", usable > 0 ? 100.0 * used / usable : 0.0},
                   {"pieces", pieces.size()},
                   {"jobs", std::vector<std::string>(jobs.begin(), jobs.end())}});
  }
  return out;
}

const fs::path& stock_dir(const WoodPlaces& places) {
  if (!places.stock)
    throw WoodError("the parquetry kind keeps no stock (its `stock` parameter is empty)");
  return *places.stock;
}

// Runs `change` on the stock under the StockLock, or says the stock is busy.
template <class F>
void with_stock_lock(const WoodPlaces& places, F change) {
  TimedStockLock lock(stock_dir(places), places.lock_wait);
  if (!lock.held()) {
    throw WoodError("the wood stock is busy: a parquetry plan is running" +
                    (places.busy_hint.empty() ? std::string() : " (" + places.busy_hint + ")") +
                    "; try again when it is converted");
  }
  try {
    change();
  } catch (const WoodError&) {
    throw;
  } catch (const std::exception& e) {
    throw WoodError(e.what());
  }
}

std::string text_arg(const nlohmann::json& args, const char* key, bool required) {
  if (!args.contains(key)) {
    if (required) throw WoodError(std::string("wood needs \"") + key + "\"");
    return "";
  }
  if (!args[key].is_string()) throw WoodError(std::string("wood: \"") + key + "\" must be a string");
  return args[key].get<std::string>();
}

const fs::path& folder_for_change(const Wood& wood) {
  if (!wood.params.wood_folder)
    throw WoodError("the parquetry wood is a list of sheets in the configuration; add or remove sheets "
                    "there (then reload with SIGHUP)");
  return *wood.params.wood_folder;
}

}  // namespace

// The client's scan (and mask) copied into places.staging, removed again when it dies.
class StagedScans {
 public:
  StagedScans(const WoodPlaces& places, const std::string& image, const std::string& mask, WoodScans& scans) {
    if (!scans.image.valid()) throw WoodError("wood add: the scan " + image + " was not passed");
    if (!mask.empty() && !scans.mask.valid()) throw WoodError("wood add: the mask " + mask + " was not passed");
    // Under the client's own file names (messages name them), one folder each.
    image_ = stage(places, "scan", image, scans.image.get());
    try {
      if (!mask.empty()) mask_ = stage(places, "mask", mask, scans.mask.get());
    } catch (...) {
      std::error_code ec;
      fs::remove(image_, ec);
      throw;
    }
  }
  ~StagedScans() {
    std::error_code ec;
    if (!image_.empty()) fs::remove(image_, ec);
    if (!mask_.empty()) fs::remove(mask_, ec);
  }
  const fs::path& image() const { return image_; }
  static fs::path stage(const WoodPlaces& places, const char* what, const std::string& path, int fd) {
    const std::string name = client_file_name(path);
    std::error_code ec;
    fs::create_directories(places.staging / what, ec);
    if (ec) throw WoodError((places.staging / what).string() + ": cannot create: " + ec.message());
    const fs::path dest = places.staging / what / name;
    copy_client_file(fd, name, dest, places.limits.max_file_bytes);
    return dest;
  }
  const fs::path& mask() const { return mask_; }

 private:
  fs::path image_, mask_;
};

nlohmann::json wood_request(const WoodPlaces& places, const nlohmann::json& args, WoodScans scans) {
  const std::string action = text_arg(args, "action", true);
  if (action == "list") {
    const Wood wood = read_wood(places);
    parquetry::Stock stock;
    if (places.stock) {
      try {
        stock = load_stock(*places.stock);  // saved atomically: readable without the lock
      } catch (const std::exception& e) {
        throw WoodError(e.what());
      }
    }
    return {{"wood", wood.params.wood_folder ? wood.params.wood_folder->string() : "list"},
            {"stock", places.stock ? places.stock->string() : ""},
            {"sheets", sheets_json(places, wood, stock)}};
  }
  std::string done;
  if (action == "add") {
    const std::string image = text_arg(args, "image", true);
    const std::string mask = text_arg(args, "mask", false);
    if (!fs::path(image).is_absolute() || (!mask.empty() && !fs::path(mask).is_absolute()))
      throw WoodError("wood add needs absolute paths");
    std::string id = text_arg(args, "id", false);
    if (id.empty()) id = fs::path(image).stem().string();
    Wood wood = read_wood(places);
    double dpi = wood.params.dpi;
    if (args.contains("dpi")) {
      if (!args["dpi"].is_number() || !(args["dpi"].get<double>() > 0))
        throw WoodError("wood add: \"dpi\" must be a positive number");
      dpi = args["dpi"].get<double>();
    }
    const fs::path folder = folder_for_change(wood);
    for (const auto& e : wood.entries)
      if (e.id == id)
        throw WoodError("a sheet '" + id + "' is already in " + folder.string() +
                        "; remove it first or choose another --id");
    // Read with the client's rights: the files it opened, copied to our staging folder.
    const StagedScans staged(places, image, mask, scans);
    // The library file is rewritten under the stock lock too: one writer at a time.
    with_stock_lock(places, [&] { add_sheet(folder, id, staged.image(), dpi, staged.mask()); });
    done = "added sheet " + id + " (" + image + ", " + std::to_string(static_cast<int>(dpi + 0.5)) + " dpi)";
  } else if (action == "remove") {
    const std::string id = text_arg(args, "id", true);
    const bool force = args.value("force", false);
    Wood wood = read_wood(places);
    const fs::path folder = folder_for_change(wood);
    with_stock_lock(places, [&] {
      parquetry::Stock stock = load_stock(stock_dir(places));
      auto it = stock.used.find(id);
      if (it != stock.used.end() && !it->second.empty()) {
        if (!force) {
          std::set<std::string> jobs;
          for (const auto& p : it->second) jobs.insert(p.job);
          std::string list;
          for (const auto& j : jobs) list += (list.empty() ? "" : ", ") + j;
          throw WoodError("sheet " + id + " has " + std::to_string(it->second.size()) +
                          " pieces planned by job(s) " + list +
                          "; cut them first, or remove it anyway with --force");
        }
      }
      remove_sheet(folder, id);
      if (it != stock.used.end()) {
        stock.used.erase(it);
        save_stock(stock_dir(places), stock);
      }
    });
    done = "removed sheet " + id;
  } else if (action == "reset") {
    const std::string id = text_arg(args, "id", false);
    std::string job;
    if (args.contains("job")) {
      // Jobs are labelled by their id in the daemon; accept the number as well.
      job = args["job"].is_number_integer() ? std::to_string(args["job"].get<int64_t>())
                                            : text_arg(args, "job", false);
    }
    size_t removed = 0;
    with_stock_lock(places, [&] {
      parquetry::Stock stock = load_stock(stock_dir(places));
      if (!id.empty() && !stock.used.count(id))
        throw WoodError("no used wood is recorded on sheet '" + id + "'");
      for (auto it = stock.used.begin(); it != stock.used.end();) {
        if (!id.empty() && it->first != id) {
          ++it;
          continue;
        }
        auto& pieces = it->second;
        const size_t before = pieces.size();
        if (job.empty()) pieces.clear();
        else
          pieces.erase(std::remove_if(pieces.begin(), pieces.end(),
                                      [&](const parquetry::UsedPiece& p) { return p.job == job; }),
                       pieces.end());
        removed += before - pieces.size();
        it = pieces.empty() ? stock.used.erase(it) : std::next(it);
      }
      save_stock(stock_dir(places), stock);
    });
    done = "freed " + std::to_string(removed) + " pieces" + (id.empty() ? "" : " on sheet " + id) +
           (job.empty() ? "" : " of job " + job);
  } else {
    throw WoodError("unknown wood action '" + action + "'; use list, add, remove or reset");
  }
  const Wood wood = read_wood(places);
  parquetry::Stock stock;
  if (places.stock) stock = load_stock(*places.stock);
  return {{"done", done}, {"sheets", sheets_json(places, wood, stock)}};
}

}  // namespace atelier
