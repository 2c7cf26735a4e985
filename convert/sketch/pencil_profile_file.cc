#include "convert/sketch/pencil_profile_file.h"

#include "convert/common/display_text.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <toml++/toml.h>

#include "algorithms/pencil/reference_scan.h"
#include "convert/convert.h"
#include "convert/common/param_table.h"

namespace atelier {

namespace {

constexpr int kLevels = 256;
// The largest profile profile_to_toml can write (all 65536 ccm cells, 13-digit counts) is under
// 2 MiB; TOML parsing costs ~40 bytes of memory per byte of text (a 15 MiB file of one long
// array took 630 MB), so anything much larger is refused before parsing.
constexpr std::uintmax_t kMaxProfileBytes = 4u << 20;

// The shortest text that reads back as exactly `v`, always with a '.' or exponent (TOML float).
std::string exact_double(double v) {
  char buf[64];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  std::string s(buf, end);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

// The whole count behind a normalised value; throws if it is not (close to) a whole number.
long long whole_count(double normalised, long long total, const char* what) {
  const double c = normalised * static_cast<double>(total);
  const long long n = std::llround(c);
  if (std::abs(c - static_cast<double>(n)) > 1e-6 * std::max(1.0, c))
    throw std::invalid_argument(std::string("profile_to_toml: ") + what + " is not a whole count over its total");
  return n;
}

void write_hist(std::ostringstream& out, const char* key, const std::vector<double>& hist, long long total) {
  out << key << " = [\n";
  for (int row = 0; row < kLevels; row += 16) {
    out << " ";
    for (int i = row; i < row + 16; ++i) out << " " << whole_count(hist[i], total, key) << ",";
    out << "  # " << row << ".." << row + 15 << "\n";
  }
  out << "]\n";
}

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\', out += c;
    else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else out += c;
  }
  return out + "\"";
}

// Strict reading of one profile table. Errors are ConvertErrors "SOURCE:LINE: key 'K': ...".
class ProfileReader {
 public:
  ProfileReader(const toml::table& t, const std::string& source) : source_(source), r_(t, source, "") {}

  [[noreturn]] void fail(const std::string& key, const std::string& problem) const { r_.fail(key, problem); }
  [[noreturn]] void fail_at(const toml::node& n, const std::string& key, const std::string& problem) const {
    throw ParamError(where(n, source_) + "key '" + key + "': " + problem);
  }

  void require(const std::string& key) {
    if (!r_.has(key)) fail(key, "missing (a profile file needs it)");
  }
  std::string string(const std::string& key) {
    require(key);
    return r_.get_string(key, "");
  }
  long long integer(const std::string& key, long long lo, long long hi) {
    require(key);
    return r_.get_int(key, 0, lo, hi);
  }
  double number(const std::string& key, double lo, double hi) {
    require(key);
    return r_.get_double(key, 0, lo, hi);
  }

  // 256 whole counts that add up to `total`; returned normalised by it.
  std::vector<double> hist(const std::string& key, long long total) {
    require(key);
    const toml::array* a = r_.get_array(key);
    if (a->size() != static_cast<size_t>(kLevels))
      fail(key, "expected " + std::to_string(kLevels) + " counts (one per grey level), got " + std::to_string(a->size()));
    std::vector<double> out(kLevels, 0.0);
    long long sum = 0;
    for (int i = 0; i < kLevels; ++i) {
      const toml::node& n = *a->get(static_cast<size_t>(i));
      auto v = n.value_exact<int64_t>();
      if (!v) fail_at(n, key, "grey level " + std::to_string(i) + ": expected a whole count");
      if (*v < 0) fail_at(n, key, "grey level " + std::to_string(i) + ": count " + std::to_string(*v) + " is negative");
      // No count above the total (so the sum below cannot overflow and wrap round to it).
      if (*v > total)
        fail_at(n, key, "grey level " + std::to_string(i) + ": count " + std::to_string(*v) + " is more than the " +
                            std::to_string(total) + " pixels stated");
      sum += *v;
      out[i] = static_cast<double>(*v);
    }
    if (sum != total)
      fail(key, "the counts add up to " + std::to_string(sum) + ", not the " + std::to_string(total) + " pixels stated");
    for (double& x : out) x /= static_cast<double>(total);
    return out;
  }

  // Sparse [i, j, count] cells; returned as the normalised 256 x 256 matrix and the total.
  std::vector<double> ccm(const std::string& key, long long* total) {
    require(key);
    const toml::array* a = r_.get_array(key);
    std::vector<double> out(kLevels * kLevels, 0.0);
    *total = 0;
    for (const toml::node& cell : *a) {
      const toml::array* t = cell.as_array();
      if (!t || t->size() != 3) fail_at(cell, key, "expected [i, j, count] triples");
      int64_t v[3];
      for (int k = 0; k < 3; ++k) {
        auto x = t->get(static_cast<size_t>(k))->value_exact<int64_t>();
        if (!x) fail_at(cell, key, "expected [i, j, count] with whole numbers");
        v[k] = *x;
      }
      const std::string entry = "[" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " + std::to_string(v[2]) + "]";
      for (int k = 0; k < 2; ++k)
        if (v[k] < 0 || v[k] >= kLevels)
          fail_at(cell, key, "entry " + entry + ": grey level " + std::to_string(v[k]) + " is outside 0..255");
      if (v[2] < 1 || v[2] > (int64_t{1} << 40)) fail_at(cell, key, "entry " + entry + ": count must be 1 .. 2^40");
      double& slot = out[static_cast<size_t>(v[0] * kLevels + v[1])];
      if (slot != 0.0) fail_at(cell, key, "entry " + entry + ": pair listed twice");
      slot = static_cast<double>(v[2]);
      *total += v[2];
    }
    if (*total > 0)
      for (double& x : out) x /= static_cast<double>(*total);
    return out;
  }

  void finish() { r_.finish(); }

 private:
  std::string source_;
  TableReader r_;
};

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::string joined(const std::vector<std::string>& names) {
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  return list;
}

// The embedded profiles, parsed once (the static is initialised thread-safely).
const std::map<std::string, pencil::PencilProfile>& parsed_shipped() {
  static const std::map<std::string, pencil::PencilProfile> profiles = [] {
    std::map<std::string, pencil::PencilProfile> m;
    for (const auto& [stem, text] : detail::embedded_pencil_files())
      m.emplace(std::string(stem), profile_from_toml(text, "data/pencils/" + std::string(stem) + ".toml"));
    return m;
  }();
  return profiles;
}

}  // namespace

std::string profile_to_toml(const pencil::PencilProfile& p, const std::string& source) {
  if (p.mid_hist.size() != static_cast<size_t>(kLevels) || p.hist.size() != static_cast<size_t>(kLevels) ||
      p.ccm.size() != static_cast<size_t>(kLevels * kLevels))
    throw std::invalid_argument("profile_to_toml: need 256-bin histograms and a 256 x 256 ccm");
  if (p.mid_pixels <= 0 || p.line_pixels <= 0 || p.ccm_pairs < 0)
    throw std::invalid_argument("profile_to_toml: the profile has no pixel counts (learn it with learn_profile)");
  std::ostringstream out;
  out << "# atelier pencil profile: the statistics of one pencil's lines (Meraj et al. 2008,\n"
         "# \"Mimicking Hand-Drawn Pencil Lines\", section 3.2), as learned by `atelier-convert\n"
         "# pencil-profile` from lines running vertically on white paper.\n"
         "# Grey levels 0 (black) .. 255 (white); counts are pixels.\n# Learned from: "
      << (source.empty() ? "(not recorded)" : source) << "\n"
      << "format = " << quoted(std::string(kPencilProfileFormat)) << "\n"
      << "name = " << quoted(p.name) << "\n"
      << "source = " << quoted(source) << "\n"
      << "width_px = " << exact_double(p.width_px) << "  # mean run of line pixels across the line\n"
      << "min_mid = " << p.min_mid << "  # centre grey levels (darkest pixel of each run)\n"
      << "max_mid = " << p.max_mid << "\n"
      << "min_range = " << p.min_range << "  # the whole line's grey levels\n"
      << "max_range = " << p.max_range << "\n"
      << "mid_pixels = " << p.mid_pixels << "  # centre pixels counted in mid_hist\n"
      << "line_pixels = " << p.line_pixels << "  # line pixels counted in hist\n"
      << "# Pixels per grey level, 16 levels a line.\n";
  write_hist(out, "mid_hist", p.mid_hist, p.mid_pixels);
  write_hist(out, "hist", p.hist, p.line_pixels);
  out << "# Co-occurrence along the line: [i, j, count] = how often grey level i lies directly\n"
         "# above grey level j (line vertical); only the non-zero cells, "
      << p.ccm_pairs << " pairs in all.\nccm = [\n";
  int on_line = 0;
  for (int i = 0; i < kLevels; ++i) {
    for (int j = 0; j < kLevels; ++j) {
      const double v = p.ccm[static_cast<size_t>(i * kLevels + j)];
      if (v == 0.0) continue;
      if (on_line == 0) out << " ";
      out << " [" << i << ", " << j << ", " << whole_count(v, p.ccm_pairs, "ccm") << "],";
      if (++on_line == 8) out << "\n", on_line = 0;
    }
  }
  if (on_line) out << "\n";
  out << "]\n";
  return out.str();
}

pencil::PencilProfile profile_from_toml(std::string_view text, const std::string& source) {
  toml::table t;
  try {
    t = toml::parse(text, std::string_view{source});
  } catch (const toml::parse_error& e) {
    throw ConvertError(toml_error_text(e, source));
  }
  try {
    ProfileReader r(t, source);
    if (r.string("format") != kPencilProfileFormat)
      r.fail("format", "expected \"" + std::string(kPencilProfileFormat) + "\" (a file of another version or kind)");
    pencil::PencilProfile p;
    p.name = r.string("name");
    if (p.name.empty()) r.fail("name", "must not be empty");
    r.string("source");
    p.width_px = r.number("width_px", 0.1, 1000.0);
    p.min_mid = static_cast<int>(r.integer("min_mid", 0, 255));
    p.max_mid = static_cast<int>(r.integer("max_mid", p.min_mid, 255));
    p.min_range = static_cast<int>(r.integer("min_range", 0, 255));
    p.max_range = static_cast<int>(r.integer("max_range", p.min_range, 255));
    p.mid_pixels = r.integer("mid_pixels", 1, int64_t{1} << 40);
    p.line_pixels = r.integer("line_pixels", p.mid_pixels, int64_t{1} << 40);
    p.mid_hist = r.hist("mid_hist", p.mid_pixels);
    p.hist = r.hist("hist", p.line_pixels);
    p.ccm = r.ccm("ccm", &p.ccm_pairs);
    r.finish();
    return p;
  } catch (const ParamError& e) {
    throw ConvertError(e.what());
  }
}

pencil::PencilProfile load_profile_file(const std::filesystem::path& file) {
  return load_profile_file(PathAccess(), file);
}

pencil::PencilProfile load_profile_file(const PathAccess& access, const std::filesystem::path& file) {
  // read_text refuses folders, FIFOs and files over the limit, naming the file.
  const std::string text = access.read_text(file, kMaxProfileBytes);
  return profile_from_toml(text, safe_text(file.string()));
}

const std::vector<std::string>& shipped_pencils() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const auto& [stem, text] : detail::embedded_pencil_files()) out.emplace_back(stem);
    // Light to dark as the grade models are; any other file after them, by name.
    auto rank = [](const std::string& n) {
      const auto& models = pencil::grade_models();
      for (size_t i = 0; i < models.size(); ++i)
        if (models[i].name == n) return i;
      return models.size();
    };
    std::sort(out.begin(), out.end(), [&](const std::string& a, const std::string& b) {
      return std::make_pair(rank(a), a) < std::make_pair(rank(b), b);
    });
    return out;
  }();
  return names;
}

pencil::PencilProfile shipped_pencil(const std::string& name) {
  const auto& profiles = parsed_shipped();
  for (const auto& [stem, profile] : profiles)
    if (upper(stem) == upper(name)) return profile;
  throw std::invalid_argument("unknown pencil '" + name + "' (shipped: " + joined(shipped_pencils()) + ")");
}

pencil::PencilProfile resolve_pencil(const std::string& value, const std::filesystem::path& base_dir,
                                     const std::string& source) {
  return open_pencil(value, PathAccess({}, "", "", base_dir), source);
}

pencil::PencilProfile open_pencil(const std::string& value, const PathAccess& access,
                                     const std::string& source) {
  const std::string prefix = display_path(source) + ": key 'pencil': ";
  for (const auto& name : shipped_pencils())
    if (upper(name) == upper(value)) return shipped_pencil(name);
  const std::filesystem::path file(value);
  if (file.extension() != ".toml")
    throw ConvertError(prefix + "'" + display_value(value) + "' is neither a shipped pencil (" +
                       joined(shipped_pencils()) + ") nor a .toml profile file");
  try {
    return load_profile_file(access.relabeled("", ""), access.resolve(file));
  } catch (const ConvertError& e) {
    throw ConvertError(prefix + e.what());
  }
}

}  // namespace atelier
