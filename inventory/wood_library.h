// The workshop's wood library on disk: a folder of scanned veneer sheets, or an explicit list
// of sheets given as the `wood` parameter, and their decoding into parquetry::Sheet.
//
// A wood folder holds a `library.toml`:
//   [[sheet]]
//   id = "maple_dark"            required, unique; a file-name-safe word ([A-Za-z0-9_.-])
//   image = "maple_dark.png"     required, relative to the folder
//   mask = "maple_dark.mask.png" optional; 8-bit, the scan's size, white = usable veneer
//   dpi = 300                    optional (default: the caller's default_dpi), in (0, 10000]
// Without library.toml, every image file in the folder (png jpg jpeg tif tiff bmp webp) not
// named *.mask.* is a sheet: id = file stem, mask = "<stem>.mask.png" when present,
// dpi = default_dpi.
//
// Units: dpi = scan pixels per inch. Errors: ConvertError naming the file and the problem.
// Not thread-safe for the same folder (add_sheet/remove_sheet rewrite library.toml; callers
// serialise them, e.g. under the StockLock of stock_store.h); list/load are read-only.
#pragma once

#include <filesystem>
#include <string>
#include <toml++/toml.h>
#include <vector>

#include "algorithms/parquetry/sheet.h"
#include "convert/common/convert_error.h"
#include "convert/common/image_input.h"
#include "convert/common/job_paths.h"

namespace atelier {

struct SheetEntry {
  std::string id;
  std::filesystem::path image;  // absolute or relative to the process's cwd
  std::filesystem::path mask;   // empty = the whole scan is usable
  double dpi = 300;
};

// The sheets of a wood folder (see above), sorted by id. Throws ConvertError naming the file
// and problem (missing folder, bad TOML, a missing image, repeated id, ...).
std::vector<SheetEntry> list_sheets(const std::filesystem::path& folder, double default_dpi);
// The same with every file (the folder, library.toml, the scans and masks it names) opened
// through `access` (convert/common/job_paths.h: confined to the spool when a job named the
// folder; relative `folder` from access's base).
std::vector<SheetEntry> list_sheets(const PathAccess& access, const std::filesystem::path& folder,
                                    double default_dpi);

// The `wood` parameter given as a TOML array of tables {id, image, mask?, dpi?}; relative
// paths are taken against `base`. `source` names the parameters' file for messages.
// Sorted by id. Throws ConvertError.
std::vector<SheetEntry> sheets_from_toml(const toml::array& list, const std::filesystem::path& base,
                                         double default_dpi, const std::string& source);

// Decodes the scans to BGR (image_input limits apply; grey or BGRA scans are converted) and
// the masks to CV_8UC1 (255 = usable; a mask must be the scan's size). ConvertError naming
// the file.
// `access`: how the files are opened (default: as given).
std::vector<parquetry::Sheet> load_sheets(const std::vector<SheetEntry>& entries,
                                          const ImageLimits& limits, const PathAccess& access = PathAccess());

// Copies `image` (and `mask` if not empty) into `folder` as <id>.<ext> / <id>.mask.png and
// adds or replaces the [[sheet]] entry of `id` in folder/library.toml (created from the
// folder's current sheets if missing), atomically (temporary file + rename). Validates that
// the image (and mask) decode and that the mask has the image's size. Creates the folder.
// Throws ConvertError.
void add_sheet(const std::filesystem::path& folder, const std::string& id,
               const std::filesystem::path& image, double dpi, const std::filesystem::path& mask);

// Removes the sheet's entry from library.toml (created first if missing) and the files that
// add_sheet copied for it (<id>.<ext>, <id>.mask.png inside the folder). Throws ConvertError
// if the id is unknown.
void remove_sheet(const std::filesystem::path& folder, const std::string& id);

}  // namespace atelier
