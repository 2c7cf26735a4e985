#include "inventory/wood_library.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>

#include "convert/common/display_text.h"
#include "convert/common/output_files.h"
#include "convert/common/param_table.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;

constexpr const char* kLibraryFile = "library.toml";

// One [[sheet]] entry as written: paths as given (relative to the folder), dpi only if set,
// so a library created from a scanned folder keeps following the caller's default dpi.
struct RawEntry {
  std::string id;
  std::string image;
  std::string mask;
  std::optional<double> dpi;
};

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool is_image_extension(const fs::path& p) {
  static const std::vector<std::string> exts{".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".webp"};
  const std::string e = lower(p.extension().string());
  return std::find(exts.begin(), exts.end(), e) != exts.end();
}

// Ids name output files (cuts-<id>.svg) and stock entries: one safe word.
std::optional<std::string> id_problem(const std::string& id) {
  if (id.empty()) return "is empty";
  if (id.size() > 100) return "is longer than 100 characters";
  if (id.front() == '.' || id.front() == '-') return "must not start with '.' or '-'";
  for (char c : id) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-' && c != '.') {
      return "may only contain letters, digits, '_', '-' and '.'";
    }
  }
  return std::nullopt;
}

// "<where>sheet 'x': id ..." for a bad id.
void check_id(const std::string& id, const std::string& where) {
  if (auto problem = id_problem(id)) {
    throw ConvertError(where + "sheet id '" + id + "' " + *problem);
  }
}

// Reads one [[sheet]] table strictly; `where` prefixes messages.
RawEntry read_entry(const toml::node& node, const std::string& source) {
  const std::string at = where(node, source);
  const toml::table* t = node.as_table();
  if (!t) throw ConvertError(at + "each sheet must be a table {id, image, mask, dpi}");
  RawEntry e;
  for (const auto& [k, v] : *t) {
    const std::string key(k.str());
    const std::string vat = where(v, source);
    if (key == "id" || key == "image" || key == "mask") {
      auto s = v.value_exact<std::string>();
      if (!s) throw ConvertError(vat + "sheet key '" + key + "': expected a string");
      (key == "id" ? e.id : key == "image" ? e.image : e.mask) = *s;
    } else if (key == "dpi") {
      std::optional<double> d;
      if (auto f = v.value_exact<double>()) d = *f;
      else if (auto i = v.value_exact<int64_t>()) d = static_cast<double>(*i);
      if (!d || !(*d > 0 && *d <= 10000)) {
        throw ConvertError(vat + "sheet key 'dpi': expected a number in (0, 10000]");
      }
      e.dpi = d;
    } else {
      throw ConvertError(vat + "unknown sheet key '" + key + "' (known: id, image, mask, dpi)");
    }
  }
  if (e.id.empty() && !t->contains("id")) throw ConvertError(at + "sheet without an id");
  check_id(e.id, at);
  if (e.image.empty()) throw ConvertError(at + "sheet '" + e.id + "' has no image");
  return e;
}

SheetEntry resolve(const RawEntry& raw, const fs::path& base, double default_dpi) {
  SheetEntry e;
  e.id = raw.id;
  e.image = fs::path(raw.image).is_absolute() ? fs::path(raw.image) : base / raw.image;
  if (!raw.mask.empty()) e.mask = fs::path(raw.mask).is_absolute() ? fs::path(raw.mask) : base / raw.mask;
  e.dpi = raw.dpi.value_or(default_dpi);
  return e;
}

void check_unique(std::vector<RawEntry>& entries, const std::string& source) {
  std::sort(entries.begin(), entries.end(), [](const RawEntry& a, const RawEntry& b) { return a.id < b.id; });
  for (size_t i = 1; i < entries.size(); ++i) {
    if (entries[i].id == entries[i - 1].id) {
      throw ConvertError(source + ": sheet id '" + entries[i].id + "' is used twice (" +
                         entries[i - 1].image + ", " + entries[i].image + ")");
    }
  }
}

// A library.toml lists sheets: a few kilobytes; anything far larger is not one.
constexpr uint64_t kMaxLibraryBytes = 4u << 20;

std::vector<RawEntry> read_library_file(const PathAccess& access, const fs::path& file) {
  const std::string source = display_path(file);
  toml::table root;
  try {
    const std::string text = access.read_text(file, kMaxLibraryBytes);
    root = toml::parse(text, std::string_view{source});
  } catch (const toml::parse_error& e) {
    throw ConvertError(toml_error_text(e, source));
  }
  std::vector<RawEntry> entries;
  for (const auto& [k, v] : root) {
    if (k.str() != "sheet") {
      throw ConvertError(where(v, source) + "unknown key '" + std::string(k.str()) +
                         "' (a wood library holds [[sheet]] tables)");
    }
    const toml::array* list = v.as_array();
    if (!list) throw ConvertError(where(v, source) + "'sheet' must be [[sheet]] tables");
    for (const auto& n : *list) entries.push_back(read_entry(n, source));
  }
  check_unique(entries, source);
  return entries;
}

// The sheets of a folder without library.toml: every image not named *.mask.*.
// Regular files only (list_files does not follow symlinks).
std::vector<RawEntry> scan_folder(const PathAccess& access, const fs::path& folder) {
  std::vector<RawEntry> entries;
  const std::vector<std::string> files = access.list_files(folder);
  for (const std::string& name : files) {
    const fs::path file(name);
    if (!is_image_extension(file)) continue;
    const std::string stem = file.stem().string();
    if (stem.empty() || stem.front() == '.') continue;  // hidden and temporary files
    if (lower(fs::path(stem).extension().string()) == ".mask") continue;
    RawEntry e;
    e.id = stem;
    check_id(e.id, display_path(folder / file) + ": ");
    e.image = name;
    if (std::find(files.begin(), files.end(), stem + ".mask.png") != files.end()) e.mask = stem + ".mask.png";
    entries.push_back(e);
  }
  check_unique(entries, display_path(folder));
  return entries;
}

void check_folder(const PathAccess& access, const fs::path& folder) {
  if (access.is_dir(folder)) return;
  std::error_code ec;
  if (!access.confined() && !fs::exists(folder, ec))
    throw ConvertError(access.prefix(folder) + "no such wood folder");
  access.open_dir(folder);  // throws why (outside the spool, a symlink, not a folder, ...)
  throw ConvertError(access.prefix(folder) + "no such wood folder");
}

bool has_library(const PathAccess& access, const fs::path& folder) {
  return access.is_file(folder / kLibraryFile);
}

std::vector<RawEntry> raw_entries(const PathAccess& access, const fs::path& folder) {
  check_folder(access, folder);
  const std::vector<std::string> files = access.list_files(folder);
  if (std::find(files.begin(), files.end(), kLibraryFile) != files.end())
    return read_library_file(access, folder / kLibraryFile);
  return scan_folder(access, folder);
}

void write_library(const fs::path& folder, const std::vector<RawEntry>& entries) {
  toml::array sheets;
  for (const RawEntry& e : entries) {
    toml::table t;
    t.insert("id", e.id);
    t.insert("image", e.image);
    if (!e.mask.empty()) t.insert("mask", e.mask);
    if (e.dpi) t.insert("dpi", *e.dpi);
    sheets.push_back(std::move(t));
  }
  toml::table root;
  root.insert("sheet", std::move(sheets));
  std::ostringstream out;
  out << "# Wood library: one [[sheet]] per scanned veneer sheet (atelierctl wood add|remove).\n"
      << "# Paths are relative to this folder; dpi is the scan's resolution.\n\n"
      << root << "\n";
  write_output(folder / kLibraryFile, out.str());
}

cv::Mat to_bgr8(const cv::Mat& m) {
  cv::Mat eight = m;
  if (m.depth() == CV_16U) m.convertTo(eight, CV_8U, 1.0 / 257);
  else if (m.depth() != CV_8U) m.convertTo(eight, CV_8U);
  cv::Mat bgr;
  if (eight.channels() == 1) cv::cvtColor(eight, bgr, cv::COLOR_GRAY2BGR);
  else if (eight.channels() == 4) cv::cvtColor(eight, bgr, cv::COLOR_BGRA2BGR);
  else bgr = eight;
  return bgr;
}

// A mask as CV_8UC1, 255 = usable (grey above half).
cv::Mat to_mask(const cv::Mat& m) {
  cv::Mat grey;
  cv::cvtColor(to_bgr8(m), grey, cv::COLOR_BGR2GRAY);
  cv::Mat mask;
  cv::threshold(grey, mask, 127, 255, cv::THRESH_BINARY);
  return mask;
}

bool same_file(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  return fs::equivalent(a, b, ec);
}

// Removes `name` from `folder` if it is a file there that add_sheet made for `id`.
void remove_copied(const fs::path& folder, const std::string& id, const std::string& name) {
  if (name.empty()) return;
  const fs::path p(name);
  if (p.has_parent_path() || p.is_absolute()) return;  // not a copy in the folder
  const std::string stem = p.stem().string();
  if (stem != id && stem != id + ".mask") return;
  std::error_code ec;
  fs::remove(folder / p, ec);
}

}  // namespace

std::vector<SheetEntry> list_sheets(const fs::path& folder, double default_dpi) {
  return list_sheets(PathAccess(), folder, default_dpi);
}

std::vector<SheetEntry> list_sheets(const PathAccess& access, const fs::path& given, double default_dpi) {
  const fs::path folder = access.resolve(given);
  std::vector<RawEntry> raw = raw_entries(access, folder);
  const bool library = has_library(access, folder);
  const std::string source = display_path(library ? folder / kLibraryFile : folder);
  std::vector<SheetEntry> out;
  for (const RawEntry& r : raw) {
    SheetEntry e = resolve(r, folder, default_dpi);
    // Opened as they will be read: a library.toml may not point a job outside the spool.
    auto check = [&](const fs::path& file, const char* what) {
      try {
        access.open_file(file);
      } catch (const ConvertError& why) {
        if (access.confined()) throw ConvertError(source + ": sheet '" + e.id + "': " + what + ": " + why.what());
        throw ConvertError(source + ": sheet '" + e.id + "': " + what + " " + display_path(file) + " not found");
      }
    };
    check(e.image, "image");
    if (!e.mask.empty()) check(e.mask, "mask");
    out.push_back(std::move(e));
  }
  return out;
}

std::vector<SheetEntry> sheets_from_toml(const toml::array& list, const fs::path& base,
                                         double default_dpi, const std::string& source) {
  std::vector<RawEntry> raw;
  for (const auto& n : list) raw.push_back(read_entry(n, source));
  check_unique(raw, source);
  std::vector<SheetEntry> out;
  for (const RawEntry& r : raw) out.push_back(resolve(r, base, default_dpi));
  return out;
}

std::vector<parquetry::Sheet> load_sheets(const std::vector<SheetEntry>& entries,
                                          const ImageLimits& limits, const PathAccess& access) {
  std::vector<parquetry::Sheet> sheets;
  for (const SheetEntry& e : entries) {
    parquetry::Sheet s;
    s.id = e.id;
    s.dpi = e.dpi;
    try {
      s.image = to_bgr8(load_image(access, e.image, limits));
    } catch (const cv::Exception& ex) {
      throw ConvertError(e.image.filename().string() + ": cannot decode the scan of sheet '" + e.id +
                         "': " + ex.err);
    }
    if (!e.mask.empty()) {
      try {
        s.usable = to_mask(load_image(access, e.mask, limits));
      } catch (const cv::Exception& ex) {
        throw ConvertError(e.mask.filename().string() + ": cannot decode the mask of sheet '" +
                           e.id + "': " + ex.err);
      }
      if (s.usable.size() != s.image.size()) {
        throw ConvertError(e.mask.filename().string() + ": the mask of sheet '" + e.id + "' is " +
                           std::to_string(s.usable.cols) + "x" + std::to_string(s.usable.rows) +
                           " px, its scan " + std::to_string(s.image.cols) + "x" +
                           std::to_string(s.image.rows) + " px; they must be the same size");
      }
    }
    sheets.push_back(std::move(s));
  }
  return sheets;
}

void add_sheet(const fs::path& folder, const std::string& id, const fs::path& image, double dpi,
               const fs::path& mask) {
  check_id(id, "");
  if (!(dpi > 0 && dpi <= 10000)) {
    throw ConvertError("sheet '" + id + "': dpi must be in (0, 10000]");
  }
  // Validate before touching the folder: the scan decodes, the mask fits it.
  SheetEntry probe{id, image, mask, dpi};
  std::vector<parquetry::Sheet> decoded = load_sheets({probe}, ImageLimits{});

  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) throw ConvertError(folder.string() + ": cannot create the wood folder: " + ec.message());
  std::vector<RawEntry> entries = raw_entries(PathAccess(), folder);
  auto old = std::find_if(entries.begin(), entries.end(), [&](const RawEntry& e) { return e.id == id; });
  const std::optional<RawEntry> replaced = old == entries.end() ? std::nullopt : std::optional(*old);
  if (old != entries.end()) entries.erase(old);

  RawEntry e;
  e.id = id;
  e.dpi = dpi;
  e.image = id + lower(image.extension().string());
  const fs::path image_dest = folder / e.image;
  if (!same_file(image, image_dest)) {
    fs::path tmp = image_dest;
    tmp += ".tmp";
    fs::copy_file(image, tmp, fs::copy_options::overwrite_existing, ec);
    if (!ec) fs::rename(tmp, image_dest, ec);
    if (ec) throw ConvertError(image.filename().string() + ": cannot copy into " + folder.string() + ": " + ec.message());
  }
  if (!mask.empty()) {
    e.mask = id + ".mask.png";
    // Stored binarised as PNG whatever it came as: the library reads <id>.mask.png.
    write_output_png(folder / e.mask, decoded.front().usable);
  }
  entries.push_back(e);
  check_unique(entries, (folder / kLibraryFile).string());
  write_library(folder, entries);

  // Files of the replaced entry that the new one no longer uses.
  if (replaced) {
    if (replaced->image != e.image) remove_copied(folder, id, replaced->image);
    if (replaced->mask != e.mask) remove_copied(folder, id, replaced->mask);
  }
}

void remove_sheet(const fs::path& folder, const std::string& id) {
  std::vector<RawEntry> entries = raw_entries(PathAccess(), folder);
  // A folder without library.toml holds the user's own scans, not copies: keep them (the
  // library written below no longer lists the sheet).
  const bool managed = fs::exists(folder / kLibraryFile);
  auto it = std::find_if(entries.begin(), entries.end(), [&](const RawEntry& e) { return e.id == id; });
  if (it == entries.end()) {
    std::string known;
    for (const RawEntry& e : entries) known += (known.empty() ? "" : ", ") + e.id;
    throw ConvertError(folder.string() + ": no sheet '" + id + "' in the wood library (sheets: " +
                       (known.empty() ? "none" : known) + ")");
  }
  const RawEntry gone = *it;
  entries.erase(it);
  write_library(folder, entries);
  if (managed) {
    remove_copied(folder, id, gone.image);
    remove_copied(folder, id, gone.mask);
  }
}

}  // namespace atelier
