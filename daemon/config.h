// atelierd's configuration (TOML, read with toml++), strict: a missing required key, a
// mistyped value or an unknown key is an error naming the file, the line and the key.
// Only `[spool] dir` is required; every other key has the default documented here and in
// config/atelierd.toml. Immutable once loaded; SIGHUP loads a new one.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <toml++/toml.h>
#include <vector>

#include "convert/common/image_input.h"

namespace atelier {

enum class WatchMode { inotify, poll };

struct DeviceConfig {
  std::string name;
  std::string driver;                // "ayab", "grbl", "file-drop"
  std::string port;                  // serial device path, or ""
  std::string usb;                   // "vvvv:pppp[:serial]", or ""
  std::string machine;               // e.g. "kh930"
  std::vector<std::string> kinds;    // job kinds this device takes
  bool autostart = false;            // a ready job starts without `atelierctl start`
                                     // (default true for knitting machines, false for lasers)
  std::string dir;                   // file-drop: target folder
  std::vector<std::string> formats;  // file-drop: file formats
  // ayab: how a pattern is laid on the needle bed (drivers/ayab/knit_plan.h).
  std::string mode = "single-bed";   // single-bed | classic-ribber | circular
  int start_needle = -1;             // leftmost needle, 1-based as on the bed; -1 = centred
  bool mirror = false;               // pattern column 0 on the rightmost needle instead
  // grbl: how G-code is streamed: "character-counting" (fast; keeps GRBL's receive buffer
  // full) or "send-response" (one line at a time, for controllers that misreport it).
  std::string streaming = "character-counting";
};

// [web]: the web page and JSON API (docs/web.md). Off unless `enabled`.
struct WebConfig {
  bool enabled = false;
  std::string listen = "127.0.0.1:8631";  // host:port as written ("[::1]:8631" for IPv6)
  std::string host = "127.0.0.1";         // parsed from `listen`, without brackets
  int port = 8631;
  // Who may connect: CIDR blocks, "localhost" or "any" (daemon/web/address_filter.h).
  // Default: ["localhost"] when `host` is a loopback address, else ["any"].
  std::vector<std::string> allow_from;
  // Names the page is reached by besides its addresses, "localhost" and the box's own name
  // (and NAME.local): a request whose Host is none of these is refused (DNS rebinding).
  std::vector<std::string> server_names;
  std::string token;                      // bearer token for scripts and logins; "" = none
  int session_hours = 12;                 // a page login lasts this long
  std::map<std::string, std::string> users;  // [web.users]: name -> crypt(3) password hash
  bool can_act() const { return !token.empty() || !users.empty(); }
};

struct Config {
  std::filesystem::path source;      // the file this was read from

  // [spool]
  std::filesystem::path spool_dir;   // required
  WatchMode watch = WatchMode::inotify;
  int settle_ms = 500;               // poll mode: size unchanged this long = complete
  // Folders besides the spool that a job's own paths (sidecar, job file, --set) may name;
  // absolute (relative ones are taken against the config file's folder). Default: none.
  std::vector<std::filesystem::path> allow_paths;
  // The spool and allow_paths: what a conversion is confined to (atelier-convert --confine).
  std::vector<std::filesystem::path> confine_dirs() const {
    std::vector<std::filesystem::path> dirs{spool_dir};
    dirs.insert(dirs.end(), allow_paths.begin(), allow_paths.end());
    return dirs;
  }

  // [store]
  std::filesystem::path store_path = "/var/lib/atelier/jobs.sqlite";
  // The daemon's state folder: the store's folder (/var/lib/atelier, systemd's
  // StateDirectory). Parquetry keeps the workshop's wood library in <state>/wood and the used
  // wood in <state>/wood-stock: `[parquetry] wood` defaults to the former (a config `wood`
  // wins), `stock` to the latter (a config `stock` wins). Relative `wood`, `stock` and sheet
  // image/mask paths in [parquetry] are made absolute against the config file's folder, since
  // the conversion reads them from its standard input.
  std::filesystem::path state_dir() const { return store_path.parent_path(); }
  // Retention (daemon/retention.h): finished jobs (completed, failed, canceled) whose last
  // change is more than keep_days days old are purged, rows and output folders, and at most
  // keep_jobs of them are kept (the most recently finished); 0 turns either limit off.
  // Checked at start-up, every hour and at once after a SIGHUP reload.
  int keep_days = 30;
  int keep_jobs = 500;

  // [control]
  std::filesystem::path socket_path = "/run/atelier/control.sock";
  std::string socket_group = "atelier";  // socket is 0660 for this group (if it exists)

  // [limits]
  ImageLimits limits;                // max_file_bytes, max_pixels
  int job_timeout_s = 600;           // a conversion running longer is killed and fails
  int workers = 2;                   // conversions at once
  int job_memory_mb = 2048;          // each conversion's memory budget (address space), MB

  // [knit] ... : each kind's default parameters, validated, merged under each job's own.
  // The laser kinds' defaults also carry the `[laser]` table under the key "laser" (layers,
  // work area, power scale), which their conversions read.
  std::map<std::string, toml::table> kind_defaults;

  // [laser] check_first: lasers dry-run every job in GRBL check mode before the real run.
  bool laser_check_first = false;

  std::vector<DeviceConfig> devices;  // [[device]]

  WebConfig web;  // [web]
};

// Reads and validates `file`. Throws ParamError ("FILE:LINE: key 'x': problem").
Config load_config(const std::filesystem::path& file);

// Same from TOML text (tests); `source` names it in errors.
Config parse_config(const std::string& text, const std::string& source);
// Same from a parsed table (the test that checks config/atelierd.toml asks which of its tables
// the readers looked at: ParamKeyLog in convert/common/param_table.h).
Config config_from_table(const toml::table& root, const std::string& source);

}  // namespace atelier
