#include "daemon/core/config.h"

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>

#include "daemon/convert/convert.h"
#include "daemon/convert/laser_params.h"
#include "daemon/convert/param_table.h"

namespace atelier {
namespace {

// Stitch-file formats a file-drop device can deliver (the embroidery conversion's design.*).
const std::vector<std::string> kDropFormats = {"dst", "exp"};

// The kinds whose conversions make laser G-code (and read the [laser] table), as far as this
// build converts them.
std::vector<std::string> laser_kinds() {
  std::vector<std::string> out;
  for (const char* k : {"cut", "parquetry", "sketch"})
    if (is_known_kind(k)) out.push_back(k);
  return out;
}

DeviceConfig read_device(const toml::table& t, const std::string& source, size_t index) {
  TableReader r(t, source, "device[" + std::to_string(index) + "]");
  DeviceConfig d;
  d.name = r.get_string("name", "");
  if (d.name.empty()) r.fail("name", "every [[device]] needs a name");
  d.driver = r.get_choice("driver", "", {"ayab", "grbl", "file-drop"});
  d.port = r.get_string("port", "");
  d.usb = r.get_string("usb", "");
  const bool knitter = d.driver == "ayab";
  const bool laser = d.driver == "grbl";
  const bool drop = d.driver == "file-drop";
  d.machine = knitter ? r.get_choice("machine", "kh930", {"kh910", "kh930", "kh270"})
                      : r.get_string("machine", "");
  d.kinds = r.get_string_list("kinds", knitter ? std::vector<std::string>{"knit"}
                                       : laser ? laser_kinds()
                                               : std::vector<std::string>{"embroidery"});
  // Writing a file is safe and quick: a file-drop device delivers without `atelierctl start`.
  d.autostart = r.get_bool("autostart", knitter || drop);
  d.dir = r.get_string("dir", "");
  d.formats = r.get_string_list("formats", drop ? kDropFormats : std::vector<std::string>{});
  if (knitter) {
    d.mode = r.get_choice("mode", "single-bed", {"single-bed", "classic-ribber", "circular"});
    d.start_needle = static_cast<int>(r.get_int("start_needle", -1, -1, 200));
    if (d.start_needle == 0) r.fail("start_needle", "needles are numbered from 1");
    d.first_row = r.get_choice("first_row", "top", {"top", "bottom"});
    d.mirror = r.get_bool("mirror", false);
  }
  if (laser) d.streaming = r.get_choice("streaming", d.streaming, {"character-counting", "send-response"});
  r.finish();
  if (knitter && d.kinds.empty()) r.fail("kinds", "a knitting machine needs at least one kind, e.g. [\"knit\"]");
  if (knitter)
    for (const auto& k : d.kinds)
      if (is_known_kind(k) && k != "knit" && k != "lace")
        r.fail("kinds", "a knitting machine knits 'knit' and 'lace' jobs, not '" + k + "'");
  if (laser) {
    const auto takes = laser_kinds();
    for (const auto& k : d.kinds)
      if (is_known_kind(k) && std::find(takes.begin(), takes.end(), k) == takes.end())
        r.fail("kinds", "a laser cannot run '" + k + "' jobs; it takes cut, parquetry and sketch");
  }
  if ((knitter || laser) && d.port.empty() && d.usb.empty())
    r.fail("name", "device '" + d.name + "' needs port = \"/dev/ttyACM0\" or usb = \"2341:0043\"");
  if (drop) {
    if (d.dir.empty())
      r.fail("dir", "file-drop device '" + d.name + "' needs dir = \"/media/EMB\" (the machine's folder)");
    if (d.formats.empty()) r.fail("formats", "give at least one of \"dst\", \"exp\"");
    for (const auto& f : d.formats)
      if (std::find(kDropFormats.begin(), kDropFormats.end(), f) == kDropFormats.end())
        r.fail("formats", "unknown format '" + f + "' (known: \"dst\", \"exp\")");
    for (const auto& k : d.kinds)
      if (k != "embroidery")
        r.fail("kinds", "a file-drop device takes embroidery jobs only, not '" + k + "'");
  }
  for (const auto& k : d.kinds)
    if (!is_known_kind(k)) r.fail("kinds", "unknown kind '" + k + "'");
  return d;
}

// An absolute path string for a path given relative to the config file's folder.
void make_absolute(toml::table& t, const std::string& key, const std::filesystem::path& base) {
  if (auto v = t[key].value_exact<std::string>(); v && !v->empty() && std::filesystem::path(*v).is_relative())
    t.insert_or_assign(key, (base / *v).lexically_normal().string());
}

// The daemon's own wood library and stock under the state folder, unless the config says
// otherwise (see Config::state_dir()).
void place_parquetry_wood(toml::table& t, const std::filesystem::path& base, const std::filesystem::path& state) {
  if (!t.contains("wood")) t.insert("wood", (state / "wood").string());
  if (!t.contains("stock")) t.insert("stock", (state / "wood-stock").string());
  make_absolute(t, "wood", base);
  make_absolute(t, "stock", base);
  if (toml::array* list = t["wood"].as_array())
    for (auto& sheet : *list)
      if (toml::table* s = sheet.as_table()) {
        make_absolute(*s, "image", base);
        make_absolute(*s, "mask", base);
      }
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
    r.finish();
  }
  if (const toml::table* store = top.get_table("store")) {
    TableReader r(*store, source, "store");
    c.store_path = r.get_string("path", c.store_path.string());
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
      for (const auto& kind : laser_kinds()) c.kind_defaults[kind].insert_or_assign("laser", *t);
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
  top.finish();
  // Relative paths are resolved against the config file's folder, not the daemon's cwd.
  const auto base = std::filesystem::path(source).parent_path();
  for (auto* p : {&c.spool_dir, &c.store_path, &c.socket_path})
    if (p->is_relative()) *p = base / *p;
  for (DeviceConfig& d : c.devices)
    if (!d.dir.empty() && std::filesystem::path(d.dir).is_relative()) d.dir = (base / d.dir).lexically_normal().string();
  // The conversion reads its parameters from standard input, where they have no file.
  if (auto it = c.kind_defaults.find("embroidery"); it != c.kind_defaults.end())
    make_absolute(it->second, "textures", base);
  if (auto it = c.kind_defaults.find("lace"); it != c.kind_defaults.end())
    make_absolute(it->second, "start_chart", base);
  if (auto it = c.kind_defaults.find("sketch"); it != c.kind_defaults.end())
    if (auto pencil = it->second["pencil"].value_exact<std::string>();
        pencil && std::filesystem::path(*pencil).extension() == ".toml")  // a file, not a grade
      make_absolute(it->second, "pencil", base);
  if (auto it = c.kind_defaults.find("parquetry"); it != c.kind_defaults.end())
    place_parquetry_wood(it->second, base, c.state_dir());
  return c;
}

}  // namespace

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
