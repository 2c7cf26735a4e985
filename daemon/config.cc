#include "daemon/config.h"

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>

#include "convert/convert.h"
#include "convert/kinds.h"
#include "convert/common/laser_params.h"
#include "convert/common/param_table.h"
#include "daemon/web/address_filter.h"

namespace atelier {
namespace {

// Stitch-file formats a file-drop device can deliver (the formats its kinds write), or those
// it delivers when its `formats` names none.
std::vector<std::string> drop_formats(bool default_only = false) {
  std::vector<std::string> out;
  for (const std::string& kind : kinds_for_driver(kFileDropDriver))
    for (std::string_view f : default_only ? find_kind(kind)->default_formats : find_kind(kind)->formats)
      if (std::find(out.begin(), out.end(), f) == out.end()) out.emplace_back(f);
  return out;
}

// "'a' and 'b'", "a, b and c": the names for a message.
std::string and_list(const std::vector<std::string>& names, bool quoted) {
  std::string out;
  for (size_t i = 0; i < names.size(); ++i) {
    if (i) out += i + 1 == names.size() ? " and " : ", ";
    out += quoted ? "'" + names[i] + "'" : names[i];
  }
  return out;
}

// "\"dst\", \"exp\"".
std::string quoted_list(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "\"" : ", \"") + n + "\"";
  return out;
}

bool contains(const std::vector<std::string>& list, const std::string& s) {
  return std::find(list.begin(), list.end(), s) != list.end();
}

DeviceConfig read_device(const toml::table& t, const std::string& source, size_t index) {
  TableReader r(t, source, "device[" + std::to_string(index) + "]");
  DeviceConfig d;
  d.name = r.get_string("name", "");
  if (d.name.empty()) r.fail("name", "every [[device]] needs a name");
  d.driver = r.get_choice("driver", "", {kAyabDriver, kGrblDriver, kFileDropDriver});
  d.port = r.get_string("port", "");
  d.usb = r.get_string("usb", "");
  const bool knitter = d.driver == kAyabDriver;
  const bool laser = d.driver == kGrblDriver;
  const bool drop = d.driver == kFileDropDriver;
  d.machine = knitter ? r.get_choice("machine", "kh930", {"kh910", "kh930", "kh270"})
                      : r.get_string("machine", "");
  d.kinds = r.get_string_list("kinds", kinds_for_driver(d.driver, /*default_only=*/true));
  // Writing a file is safe and quick: a file-drop device delivers without `atelierctl start`.
  // A knitting machine waits for the knitter (one piece at a time: cast on, then start), as
  // a laser waits for its operator.
  d.autostart = r.get_bool("autostart", drop);
  d.dir = r.get_string("dir", "");
  const std::vector<std::string> formats = drop_formats();
  d.formats = r.get_string_list("formats", drop ? drop_formats(true) : std::vector<std::string>{});
  if (knitter) {
    d.mode = r.get_choice("mode", "single-bed", {"single-bed", "classic-ribber", "circular"});
    d.start_needle = static_cast<int>(r.get_int("start_needle", -1, -1, 200));
    if (d.start_needle == 0) r.fail("start_needle", "needles are numbered from 1");
    // The row order moved to the job: chart.pdf and pattern.k are drawn for it at conversion.
    // A refused key, not a read one (t, not r: config/atelierd.toml does not document it).
    if (t.contains("first_row"))
      r.fail("first_row", "the row order is now set per job: first_row = \"bottom\" (the default) or \"top\" "
                          "in [knit] or a job's sidecar, so chart.pdf and pattern.k are made in the order "
                          "the machine knits; remove it from [[device]]");
    d.mirror = r.get_bool("mirror", false);
  }
  if (laser) d.streaming = r.get_choice("streaming", d.streaming, {"character-counting", "send-response"});
  r.finish();
  const std::vector<std::string> takes = kinds_for_driver(d.driver);
  if (knitter && d.kinds.empty())
    r.fail("kinds", "a knitting machine needs at least one kind, e.g. [\"" +
                        kinds_for_driver(d.driver, true).front() + "\"]");
  if (knitter)
    for (const auto& k : d.kinds)
      if (is_known_kind(k) && !contains(takes, k))
        r.fail("kinds", "a knitting machine knits " + and_list(takes, true) + " jobs, not '" + k + "'");
  if (laser)
    for (const auto& k : d.kinds)
      if (is_known_kind(k) && !contains(takes, k))
        r.fail("kinds", "a laser cannot run '" + k + "' jobs; it takes " + and_list(takes, false));
  if ((knitter || laser) && d.port.empty() && d.usb.empty())
    r.fail("name", "device '" + d.name + "' needs port = \"/dev/ttyACM0\" or usb = \"2341:0043\"");
  if (drop) {
    if (d.dir.empty())
      r.fail("dir", "file-drop device '" + d.name + "' needs dir = \"/media/EMB\" (the machine's folder)");
    if (d.formats.empty()) r.fail("formats", "give at least one of " + quoted_list(formats));
    for (const auto& f : d.formats)
      if (!contains(formats, f))
        r.fail("formats", "unknown format '" + f + "' (known: " + quoted_list(formats) + ")");
    for (const auto& k : d.kinds)
      if (!contains(takes, k))
        r.fail("kinds", "a file-drop device takes " + and_list(takes, false) + " jobs only, not '" + k + "'");
  }
  for (const auto& k : d.kinds)
    if (!is_known_kind(k)) r.fail("kinds", "unknown kind '" + k + "'");
  return d;
}

WebConfig read_web(const toml::table& t, const std::string& source) {
  TableReader r(t, source, "web");
  WebConfig w;
  w.enabled = r.get_bool("enabled", w.enabled);
  w.listen = r.get_string("listen", w.listen);
  try {
    const web::ListenAddress address = web::parse_listen_address(w.listen);
    w.host = address.host;
    w.port = address.port;
  } catch (const BadInput& e) {
    r.fail("listen", e.what());
  }
  w.allow_from = r.get_string_list("allow_from", web::default_allow_from(w.host));
  try {
    web::AddressFilter check(w.allow_from);
  } catch (const BadInput& e) {
    r.fail("allow_from", e.what());
  }
  w.server_names = r.get_string_list("server_names", {});
  for (const std::string& name : w.server_names)
    if (name.empty() || name.find_first_of(" /:[]") != std::string::npos)
      r.fail("server_names", "a host name such as \"workshop.example.org\", without port or scheme");
  w.token = r.get_string("token", "");
  // A short token is guessed; the page's login throttle is no defence for scripts' tokens.
  // Header values reach the server percent-decoded: a '%' would never match as sent.
  if (w.token.find_first_of("% \t\r\n") != std::string::npos)
    r.fail("token", "must not contain '%' or white space (e.g. `openssl rand -hex 24`)");
  if (!w.token.empty() && w.token.size() < 16)
    r.fail("token", "must be at least 16 characters (e.g. `openssl rand -hex 24`), or \"\" for none");
  w.session_hours = static_cast<int>(r.get_int("session_hours", w.session_hours, 1, 24 * 365));
  if (const toml::table* users = r.get_table("users")) {
    for (const auto& [name, value] : *users) {
      const std::string user(name.str());
      const auto* hash = value.as_string();
      const std::string key = "users." + user;
      // crypt(3) hashes start with $id$ ($y$ yescrypt, $6$ SHA-512, $2b$ bcrypt).
      if (!hash || hash->get().size() < 4 || hash->get().front() != '$')
        throw ParamError(where(value, source) + "key 'web." + key +
                         "': expected a crypt(3) password hash as a string, e.g. from "
                         "`atelierd --hash-password` or `mkpasswd -m yescrypt`");
      if (user.empty() || user.find_first_of(" \t\r\n:") != std::string::npos)
        throw ParamError(where(value, source) + "key 'web." + key + "': a user name has no spaces or ':'");
      w.users[user] = hash->get();
    }
  }
  r.finish();
  return w;
}

Config from_table(const toml::table& root, const std::string& source) {
  Config c;
  c.source = source;
  TableReader top(root, source, "");

  const toml::table* spool = top.get_table("spool");
  if (!spool) throw ParamError(source + ": missing section [spool] (its key 'dir' is required)");
  {
    TableReader r(*spool, source, "spool");
    if (!r.has("dir")) throw ParamError(where(*spool, source) + "key 'spool.dir' is required");
    c.spool_dir = r.get_string("dir", "");
    if (c.spool_dir.empty()) r.fail("dir", "must not be empty");
    c.watch = r.get_choice("watch", "inotify", {"inotify", "poll"}) == "poll" ? WatchMode::poll
                                                                               : WatchMode::inotify;
    c.settle_ms = static_cast<int>(r.get_int("settle_ms", 500, 50, 600000));
    for (const std::string& dir : r.get_string_list("allow_paths", {})) {
      if (dir.empty()) r.fail("allow_paths", "a folder must not be an empty string");
      c.allow_paths.emplace_back(dir);
    }
    r.finish();
  }
  if (const toml::table* store = top.get_table("store")) {
    TableReader r(*store, source, "store");
    c.store_path = r.get_string("path", c.store_path.string());
    c.keep_days = static_cast<int>(r.get_int("keep_days", c.keep_days, 0, 36500));
    c.keep_jobs = static_cast<int>(r.get_int("keep_jobs", c.keep_jobs, 0, 100000000));
    r.finish();
  }
  if (const toml::table* control = top.get_table("control")) {
    TableReader r(*control, source, "control");
    c.socket_path = r.get_string("socket", c.socket_path.string());
    c.socket_group = r.get_string("group", c.socket_group);
    r.finish();
  }
  if (const toml::table* limits = top.get_table("limits")) {
    TableReader r(*limits, source, "limits");
    c.limits.max_file_bytes = static_cast<uint64_t>(
        r.get_int("max_file_bytes", static_cast<int64_t>(c.limits.max_file_bytes), 1, INT64_MAX));
    c.limits.max_pixels = static_cast<uint64_t>(
        r.get_int("max_pixels", static_cast<int64_t>(c.limits.max_pixels), 1, INT64_MAX));
    c.job_timeout_s = static_cast<int>(r.get_int("job_timeout_s", 600, 1, 86400 * 7));
    c.workers = static_cast<int>(r.get_int("workers", 2, 1, 64));
    c.job_memory_mb = static_cast<int>(r.get_int("job_memory_mb", c.job_memory_mb, 256, 1 << 20));
    r.finish();
  }
  for (const auto& kind : known_kinds()) {
    // Validate the parsed table itself: copies of toml++ nodes lose their line numbers.
    const toml::table* t = top.get_table(kind);
    const toml::table empty;
    validate_kind_params(kind, t ? *t : empty, source);
    c.kind_defaults[kind] = t ? *t : empty;
  }
  {
    // [laser]: validated here, handed to the laser kinds' conversions under "laser".
    const toml::table* t = top.get_table("laser");
    const toml::table empty;
    c.laser_check_first = read_laser_params(t ? *t : empty, source).check_first;
    if (t)
      for (const auto& kind : kinds_for_driver(kGrblDriver)) c.kind_defaults[kind].insert_or_assign("laser", *t);
  }
  if (const toml::array* devices = top.get_array("device")) {
    size_t i = 0;
    std::set<std::string> names;
    for (const auto& el : *devices) {
      const toml::table* t = el.as_table();
      if (!t) throw ParamError(where(el, source) + "[[device]] entries must be tables");
      DeviceConfig d = read_device(*t, source, i++);
      if (!names.insert(d.name).second)
        throw ParamError(where(*t, source) + "two devices are named '" + d.name + "'");
      c.devices.push_back(std::move(d));
    }
  }
  if (const toml::table* web = top.get_table("web")) c.web = read_web(*web, source);
  else c.web.allow_from = web::default_allow_from(c.web.host);
  top.finish();
  // Relative paths are resolved against the config file's folder, not the daemon's cwd.
  const auto base = std::filesystem::path(source).parent_path();
  for (auto* p : {&c.spool_dir, &c.store_path, &c.socket_path})
    if (p->is_relative()) *p = base / *p;
  for (auto& p : c.allow_paths)
    if (p.is_relative()) p = (base / p).lexically_normal();
  for (DeviceConfig& d : c.devices)
    if (!d.dir.empty() && std::filesystem::path(d.dir).is_relative()) d.dir = (base / d.dir).lexically_normal().string();
  // The conversion reads its parameters from standard input, where they have no file.
  for (const KindInfo& kind : kinds())
    if (kind.resolve_config_paths)
      kind.resolve_config_paths(c.kind_defaults[std::string(kind.name)], base, c.state_dir());
  return c;
}

}  // namespace

Config config_from_table(const toml::table& root, const std::string& source) { return from_table(root, source); }

Config parse_config(const std::string& text, const std::string& source) {
  try {
    toml::table root = toml::parse(text, std::string_view{source});
    return from_table(root, source);
  } catch (const toml::parse_error& e) {
    std::ostringstream msg;
    msg << source << ":" << e.source().begin.line << ": " << e.description();
    throw ParamError(msg.str());
  }
}

Config load_config(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw ParamError(file.string() + ": cannot read the configuration file");
  std::stringstream buf;
  buf << in.rdbuf();
  Config c = parse_config(buf.str(), file.string());
  return c;
}

}  // namespace atelier
