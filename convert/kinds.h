// The registry of job kinds: everything the daemon, atelier-convert and the devices need to
// know about a kind, in one table. Kind names ("knit", ...) and the names of the files a
// machine is fed appear as literals only here (kinds.cc) and in the kind's own folder under
// convert/; everywhere else asks the registry (tests/unit/convert/kinds_test.cc greps the tree).
//
// To add a kind: a folder convert/<kind>/ with its params reader and converter, one entry in
// kinds.cc, and (if a machine runs it) the driver names that take it.
//
// Threading: the table is built once (function-local static) and immutable; any thread.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <toml++/toml.h>
#include <vector>

#include "convert/convert.h"

namespace atelier {

// What a job of the kind is made from.
enum class KindInput {
  image,     // a raster image (PNG, JPEG, TIFF, ...) in incoming/<kind>/
  svg,       // an SVG drawing in incoming/<kind>/
  job_file,  // a TOML job file of parameters: incoming/NAME.toml with kind = "...", or
             // NAME.toml in incoming/<kind>/ (no image)
};

// What a device reads from the job's output folder to run it on the machine.
enum class MachineInput {
  none,          // no machine runs it
  knit_pattern,  // machine_file is a PNG, 1 pixel per stitch, black = contrast yarn
  lace_chart,    // machine_file is chart.json (rows of lace symbols) for the lace carriage
  gcode,         // machine_file is a G-code program for a GRBL laser
  stitch_files,  // machine_file is a stem; the device adds ".<format>" (one of `formats`)
};

// The device drivers ([[device]] driver = "..."); the registry says which kinds each takes.
inline constexpr const char* kAyabDriver = "ayab";          // knitting machines (AYAB v6)
inline constexpr const char* kGrblDriver = "grbl";          // laser cutters (GRBL 1.1)
inline constexpr const char* kFileDropDriver = "file-drop";  // stitch files into a folder

// A device driver that can run the kind; `by_default` puts the kind in the driver's default
// `kinds` list when a [[device]] gives none.
struct DriverUse {
  std::string_view driver;  // kAyabDriver, kGrblDriver, kFileDropDriver
  bool by_default = true;
};

struct KindInfo {
  std::string_view name;  // folder under incoming/, config section [name], report's "kind"
  KindInput input = KindInput::image;
  // Validates the kind's parameter table strictly; throws ParamError naming file, line, key.
  void (*validate)(const toml::table& params, const std::string& source) = nullptr;
  // Writes every output of the kind plus report.json (see convert.h).
  ConvertResult (*convert)(const ConvertRequest& request) = nullptr;
  // Makes the kind's path-valued parameters in its config section absolute: relative to
  // `config_dir` (the config file's folder); `state_dir` holds what the daemon keeps for the
  // kind unless the config says otherwise. nullptr: the kind has no path parameters.
  void (*resolve_config_paths)(toml::table& section, const std::filesystem::path& config_dir,
                               const std::filesystem::path& state_dir) = nullptr;
  MachineInput machine_input = MachineInput::none;
  std::string_view machine_file;          // see MachineInput; empty for none
  std::vector<std::string_view> formats;  // stitch_files: the formats written ("dst", ...)
  std::vector<std::string_view> default_formats;  // those a device delivers when it names none
  std::vector<DriverUse> drivers;         // which device drivers can take it
  // Files that travel with an input NAME.EXT as NAME.EXT<suffix> (besides the .toml sidecar
  // every kind has): claimed, kept and retried with it.
  std::vector<std::string_view> companions;
  // Outputs that picture the result, best first (the web page shows them on a job's page).
  std::vector<std::string_view> previews;
  bool batches = false;    // queued jobs with equal parameters are converted together
  bool uses_wood = false;  // plans on the workshop's wood library and veneer stock
};

// Every kind this build converts, in a fixed order.
const std::vector<KindInfo>& kinds();
// nullptr for an unknown name.
const KindInfo* find_kind(std::string_view name);
// The names of kinds(), in order ({"knit", "cut", ...}).
const std::vector<std::string>& known_kinds();
bool is_known_kind(const std::string& kind);
// "knit, cut, parquetry, ..." for messages.
std::string known_kinds_text();
// Kinds whose input is a job file (KindInput::job_file).
bool converts_job_file(const std::string& kind);
// The kinds `driver` can run (default_only: those it takes when a device names none).
std::vector<std::string> kinds_for_driver(std::string_view driver, bool default_only = false);

// The suffixes of every companion file: ".toml" (the sidecar) and each kind's companions.
const std::vector<std::string>& companion_suffixes();

// Validates `params` as the parameters of `kind`; ParamError naming `source` for an unknown
// kind or a bad parameter.
void validate_kind_params(const std::string& kind, const toml::table& params,
                          const std::string& source);

}  // namespace atelier
