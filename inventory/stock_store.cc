#include "inventory/stock_store.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "convert/common/output_files.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kStockFile = "stock.json";
constexpr int kVersion = 1;

// 0.1 µm: far below the kerf, keeps the file readable.
double round4(double v) { return std::round(v * 1e4) / 1e4; }

[[noreturn]] void corrupt(const fs::path& file, const std::string& what) {
  throw ConvertError(file.string() + ": corrupt stock file: " + what +
                     " (fix or remove it; `atelierctl wood reset` starts an empty stock)");
}

parquetry::UsedPiece read_piece(const json& j, const fs::path& file, const std::string& where) {
  if (!j.is_object()) corrupt(file, where + " is not an object");
  parquetry::UsedPiece p;
  if (j.contains("job")) {
    if (!j["job"].is_string()) corrupt(file, where + ".job is not a string");
    p.job = j["job"].get<std::string>();
  }
  if (j.contains("piece")) {
    if (!j["piece"].is_number_integer()) corrupt(file, where + ".piece is not an integer");
    p.piece = j["piece"].get<int>();
  }
  if (!j.contains("polygon") || !j["polygon"].is_array()) corrupt(file, where + " has no polygon");
  for (const json& pt : j["polygon"]) {
    if (!pt.is_array() || pt.size() != 2 || !pt[0].is_number() || !pt[1].is_number()) {
      corrupt(file, where + ".polygon has a point that is not [x, y]");
    }
    const double x = pt[0].get<double>(), y = pt[1].get<double>();
    if (!std::isfinite(x) || !std::isfinite(y)) corrupt(file, where + ".polygon has a non-finite point");
    p.polygon_mm.emplace_back(x, y);
  }
  if (p.polygon_mm.size() < 3) corrupt(file, where + ".polygon has fewer than 3 points");
  return p;
}

}  // namespace

parquetry::Stock load_stock(const fs::path& dir) {
  const fs::path file = dir / kStockFile;
  parquetry::Stock stock;
  std::error_code ec;
  if (!fs::exists(file, ec)) return stock;
  std::ifstream in(file, std::ios::binary);
  if (!in) throw ConvertError(file.string() + ": cannot read: " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  json j = json::parse(text.str(), nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) corrupt(file, "not JSON");
  if (!j.is_object()) corrupt(file, "not a JSON object");
  if (!j.contains("version") || j["version"] != kVersion) {
    corrupt(file, "version is not " + std::to_string(kVersion));
  }
  if (!j.contains("sheets") || !j["sheets"].is_object()) corrupt(file, "no \"sheets\" object");
  for (const auto& [id, pieces] : j["sheets"].items()) {
    if (!pieces.is_array()) corrupt(file, "sheets." + id + " is not a list");
    auto& used = stock.used[id];
    for (size_t i = 0; i < pieces.size(); ++i) {
      used.push_back(read_piece(pieces[i], file, "sheets." + id + "[" + std::to_string(i) + "]"));
    }
  }
  return stock;
}

namespace {
void ensure_dir(const fs::path& dir, bool create) {
  std::error_code ec;
  if (!create) {
    if (!fs::is_directory(dir, ec))
      throw ConvertError(dir.string() + ": no such stock folder (atelierd creates its [parquetry] stock "
                         "folder at startup; a conversion does not create one)");
    return;
  }
  fs::create_directories(dir, ec);
  if (ec) throw ConvertError(dir.string() + ": cannot create the stock folder: " + ec.message());
}
}  // namespace

void save_stock(const fs::path& dir, const parquetry::Stock& stock, bool create) {
  ensure_dir(dir, create);
  std::error_code ec;
  if (ec) throw ConvertError(dir.string() + ": cannot create the stock folder: " + ec.message());
  nlohmann::ordered_json sheets = nlohmann::ordered_json::object();
  for (const auto& [id, pieces] : stock.used) {
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const auto& p : pieces) {
      nlohmann::ordered_json poly = nlohmann::ordered_json::array();
      for (const auto& q : p.polygon_mm) poly.push_back({round4(q.x), round4(q.y)});
      list.push_back({{"job", p.job}, {"piece", p.piece}, {"polygon", std::move(poly)}});
    }
    sheets[id] = std::move(list);
  }
  nlohmann::ordered_json root = {{"version", kVersion}, {"sheets", std::move(sheets)}};
  write_output(dir / kStockFile, root.dump(1) + "\n");
}

StockLock::StockLock(const fs::path& dir, bool create) {
  ensure_dir(dir, create);
  const fs::path file = dir / "stock.lock";
  fd_ = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw ConvertError(file.string() + ": cannot open the stock lock: " + std::strerror(errno));
  // flock locks the open file description: a second StockLock in this process waits too.
  while (::flock(fd_, LOCK_EX) != 0) {
    if (errno == EINTR) continue;
    const int err = errno;
    ::close(fd_);
    throw ConvertError(file.string() + ": cannot lock the stock: " + std::strerror(err));
  }
}

StockLock::~StockLock() {
  if (fd_ >= 0) ::close(fd_);  // closing releases the lock
}

}  // namespace atelier
