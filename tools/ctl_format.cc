#include "tools/ctl_format.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <set>
#include <sstream>
#include <vector>

#include "base/job_states.h"

namespace atelier::ctl {
namespace {

using nlohmann::json;

// The job states in lifecycle order (DESIGN.md), so counts read as a pipeline.
const std::vector<std::string> kStateOrder(kJobStateNames.begin(), kJobStateNames.end());

std::string dump(const json& value) {
  return value.dump(-1, ' ', false, json::error_handler_t::replace);
}

// A field as display text: strings as is, null/missing as "", anything else as JSON.
std::string text(const json& object, const char* key) {
  if (!object.is_object()) return "";
  auto it = object.find(key);
  if (it == object.end() || it->is_null()) return "";
  if (it->is_string()) return it->get<std::string>();
  return dump(*it);
}

std::size_t char_count(const std::string& s) {
  std::size_t n = 0;
  for (unsigned char c : s) n += (c & 0xC0) != 0x80;  // count lead bytes, not continuations
  return n;
}

// "30/120" (list) or "30/120 rows" (`with_unit`); a conversion's percent as "30%"; "-" for none.
std::string progress_text(const json& job, bool with_unit = false) {
  if (!job.is_object() || !job.contains("progress")) return "-";
  const json& p = job["progress"];
  if (!p.is_object() || !p.contains("total") || !p["total"].is_number() ||
      p["total"].get<double>() <= 0) {
    return "-";
  }
  const std::string unit = text(p, "unit");
  if (unit == "percent") return text(p, "done") + "%";
  std::string out = text(p, "done") + "/" + text(p, "total");
  if (with_unit && !unit.empty()) out += " " + unit;
  return out;
}

struct Column {
  std::string title;
  bool right_aligned = false;
};

// Columns padded to their widest cell; the last column is not padded (no trailing blanks).
std::string table(const std::vector<Column>& columns,
                  const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::size_t> width(columns.size());
  for (std::size_t c = 0; c < columns.size(); ++c) width[c] = char_count(columns[c].title);
  for (const auto& row : rows) {
    for (std::size_t c = 0; c < columns.size(); ++c) {
      width[c] = std::max(width[c], char_count(row[c]));
    }
  }
  std::string out;
  auto emit = [&](const std::vector<std::string>& cells) {
    std::string line;
    for (std::size_t c = 0; c < columns.size(); ++c) {
      std::string pad(width[c] - char_count(cells[c]), ' ');
      bool last = c + 1 == columns.size();
      if (columns[c].right_aligned) {
        line += pad + cells[c];
      } else {
        line += cells[c];
        if (!last) line += pad;
      }
      if (!last) line += "  ";
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out += line + "\n";
  };
  std::vector<std::string> titles;
  for (const auto& c : columns) titles.push_back(c.title);
  emit(titles);
  for (const auto& row : rows) emit(row);
  return out;
}

std::string duration_text(long long seconds) {
  if (seconds < 0) seconds = 0;
  long long d = seconds / 86400, h = seconds / 3600 % 24, m = seconds / 60 % 60, s = seconds % 60;
  char buf[64];
  if (d > 0) {
    std::snprintf(buf, sizeof(buf), "%lldd %02lldh %02lldm", d, h, m);
  } else if (h > 0) {
    std::snprintf(buf, sizeof(buf), "%lldh %02lldm %02llds", h, m, s);
  } else if (m > 0) {
    std::snprintf(buf, sizeof(buf), "%lldm %02llds", m, s);
  } else {
    std::snprintf(buf, sizeof(buf), "%llds", s);
  }
  return buf;
}

std::string device_job_text(const json& device) {
  if (!device.is_object() || !device.contains("job")) return "-";
  const json& job = device["job"];
  if (job.is_null() || (job.is_number() && job.get<double>() == 0) ||
      (job.is_string() && job.get<std::string>().empty())) {
    return "-";
  }
  if (job.is_object()) {
    std::string out = text(job, "id");
    const std::string progress = progress_text(job, true);
    if (progress != "-") out += " (" + progress + ")";
    return out;
  }
  return job.is_string() ? job.get<std::string>() : dump(job);
}

std::string or_dash(const std::string& s) { return s.empty() ? "-" : s; }

std::string scalar_lines(const json& object, const std::vector<std::string>& order,
                         const std::set<std::string>& skip) {
  std::vector<std::pair<std::string, std::string>> lines;
  std::set<std::string> shown;
  for (const auto& key : order) {
    if (!object.contains(key)) continue;
    shown.insert(key);
    std::string value = key == "progress" ? progress_text(object, true)
                        : key == "created" || key == "updated"
                            ? local_time(text(object, key.c_str()))
                        : (key == "estimated_s" || key == "time_left_s") && object[key].is_number()
                            ? duration_text(std::llround(object[key].get<double>()))
                            : text(object, key.c_str());
    lines.emplace_back(key == "estimated_s" ? "estimated" : key == "time_left_s" ? "time left" : key, value);
  }
  for (const auto& [key, value] : object.items()) {
    if (shown.count(key) || skip.count(key)) continue;
    lines.emplace_back(key, value.is_string() ? value.get<std::string>() : dump(value));
  }
  std::size_t width = 0;
  for (const auto& [key, value] : lines) width = std::max(width, key.size());
  std::string out;
  for (const auto& [key, value] : lines) {
    out += key + ":" + std::string(width - key.size() + 1, ' ') + or_dash(value) + "\n";
  }
  return out;
}

}  // namespace

std::string truncate_chars(const std::string& s, std::size_t max_chars) {
  if (char_count(s) <= max_chars) return s;
  std::size_t keep = max_chars > 3 ? max_chars - 3 : 0;
  std::size_t chars = 0, i = 0;
  for (; i < s.size(); ++i) {
    bool lead = (static_cast<unsigned char>(s[i]) & 0xC0) != 0x80;
    if (lead && chars++ == keep) break;  // stop before the first character we drop
  }
  return s.substr(0, i) + std::string(std::min<std::size_t>(3, max_chars), '.');
}

std::string local_time(const std::string& iso_utc, bool with_date) {
  std::tm tm{};
  int consumed = 0;
  if (std::sscanf(iso_utc.c_str(), "%4d-%2d-%2dT%2d:%2d:%2d%n", &tm.tm_year, &tm.tm_mon,
                  &tm.tm_mday, &tm.tm_hour, &tm.tm_min, &tm.tm_sec, &consumed) != 6 ||
      consumed == 0) {
    return iso_utc;
  }
  std::size_t i = static_cast<std::size_t>(consumed);
  if (i < iso_utc.size() && (iso_utc[i] == '.' || iso_utc[i] == ',')) {
    ++i;
    while (i < iso_utc.size() && std::isdigit(static_cast<unsigned char>(iso_utc[i]))) ++i;
  }
  long offset_s = 0;
  std::string zone = iso_utc.substr(i);
  if (zone == "Z" || zone == "z") {
    offset_s = 0;
  } else if (zone.size() == 6 && (zone[0] == '+' || zone[0] == '-') && zone[3] == ':') {
    int hh = 0, mm = 0;
    if (std::sscanf(zone.c_str() + 1, "%2d:%2d", &hh, &mm) != 2) return iso_utc;
    offset_s = (zone[0] == '-' ? -1L : 1L) * (hh * 3600L + mm * 60L);
  } else {
    return iso_utc;  // no zone: we cannot tell what time it names
  }
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  std::time_t t = timegm(&tm) - offset_s;
  std::tm local{};
  if (localtime_r(&t, &local) == nullptr) return iso_utc;
  char buf[32];
  std::strftime(buf, sizeof(buf), with_date ? "%Y-%m-%d %H:%M:%S" : "%H:%M:%S", &local);
  return buf;
}

std::string format_job_table(const json& jobs) {
  if (!jobs.is_array()) return format_value(jobs);
  if (jobs.empty()) return "no jobs\n";
  std::vector<std::vector<std::string>> rows;
  for (const json& job : jobs) {
    rows.push_back({text(job, "id"), text(job, "kind"), text(job, "state"), progress_text(job),
                    local_time(text(job, "updated")), text(job, "name"),
                    truncate_chars(text(job, "reason"), kListReasonChars)});
  }
  return table({{"ID", true},
                {"KIND"},
                {"STATE"},
                {"PROGRESS", true},
                {"UPDATED"},
                {"NAME"},
                {"REASON"}},
               rows);
}

std::string format_job_details(const json& job) {
  if (!job.is_object()) return format_value(job);
  std::string out = scalar_lines(job,
                                 {"id", "kind", "name", "state", "reason", "device", "progress",
                                  "time_left_s", "estimated_s", "created", "updated", "output_dir"},
                                 {"outputs", "history", "warnings"});
  // The converter's warnings, one line each, before the outputs.
  if (job.contains("warnings") && job["warnings"].is_array() && !job["warnings"].empty()) {
    out += "warnings:\n";
    for (const json& w : job["warnings"]) out += "  " + (w.is_string() ? w.get<std::string>() : dump(w)) + "\n";
  }
  if (job.contains("outputs")) {
    const json& outputs = job["outputs"];
    if (!outputs.is_array() || outputs.empty()) {
      out += "outputs: none\n";
    } else {
      out += "outputs:\n";
      for (const json& name : outputs) {
        out += "  " + (name.is_string() ? name.get<std::string>() : dump(name)) + "\n";
      }
    }
  }
  if (job.contains("history") && job["history"].is_array()) {
    out += "history:\n";
    for (const json& change : job["history"]) {
      std::string from = text(change, "from");
      std::string line = "  " + local_time(text(change, "at")) + "  " +
                         (from.empty() ? "(new)" : from) + " -> " + text(change, "to");
      std::string reason = text(change, "reason");
      if (!reason.empty()) line += " (" + reason + ")";
      out += line + "\n";
    }
  }
  return out;
}

std::string format_status(const json& status) {
  if (!status.is_object()) return format_value(status);
  std::string out = "atelierd";
  if (status.contains("version")) out += " " + text(status, "version");
  if (status.contains("pid")) out += " (pid " + text(status, "pid") + ")";
  if (status.contains("uptime_s") && status["uptime_s"].is_number()) {
    out += ", up " + duration_text(status["uptime_s"].get<long long>());
  }
  out += "\n";
  if (status.contains("spool")) {
    out += "spool:   " + text(status, "spool");
    std::vector<std::string> notes;
    if (status.contains("watch")) notes.push_back("watch " + text(status, "watch"));
    if (status.contains("workers")) notes.push_back(text(status, "workers") + " workers");
    if (!notes.empty()) {
      out += " (";
      for (std::size_t i = 0; i < notes.size(); ++i) out += (i ? ", " : "") + notes[i];
      out += ")";
    }
    out += "\n";
  }
  if (status.contains("queue") && status["queue"].is_object()) {
    const json& queue = status["queue"];
    std::vector<std::string> parts;
    auto add = [&](const std::string& state) {
      const json& n = queue[state];
      if (n.is_number() && n.get<double>() == 0) return;
      parts.push_back((n.is_string() ? n.get<std::string>() : dump(n)) + " " + state);
    };
    for (const auto& state : kStateOrder) {
      if (queue.contains(state)) add(state);
    }
    for (const auto& [state, n] : queue.items()) {
      if (std::find(kStateOrder.begin(), kStateOrder.end(), state) == kStateOrder.end()) {
        add(state);
      }
    }
    out += "queue:   ";
    if (parts.empty()) out += "empty";
    for (std::size_t i = 0; i < parts.size(); ++i) out += (i ? ", " : "") + parts[i];
    out += "\n";
  }
  if (status.contains("web") && status["web"].is_object() && status["web"].value("enabled", false)) {
    const json& web = status["web"];
    if (web.contains("url")) out += "web:     " + text(web, "url") + "\n";
    else out += "web:     not listening on " + text(web, "listen") + ": " + text(web, "error") + "\n";
  }
  const json devices = status.contains("devices") ? status["devices"] : json::array();
  if (!devices.is_array() || devices.empty()) {
    out += "devices: no devices configured\n";
  } else {
    out += "devices:\n";
    std::istringstream lines(format_devices(devices));
    for (std::string line; std::getline(lines, line);) out += "  " + line + "\n";
  }
  return out;
}

std::string format_devices(const json& devices) {
  if (!devices.is_array()) return format_value(devices);
  if (devices.empty()) return "no devices configured\n";
  std::vector<std::vector<std::string>> rows;
  for (const json& d : devices) {
    rows.push_back({text(d, "name"), text(d, "driver"), or_dash(text(d, "port")),
                    text(d, "state"), device_job_text(d),
                    or_dash(truncate_chars(text(d, "last"), kDeviceTextChars)),
                    or_dash(truncate_chars(text(d, "detail"), kDeviceTextChars))});
  }
  return table({{"NAME"}, {"DRIVER"}, {"PORT"}, {"STATE"}, {"JOB"}, {"LAST"}, {"DETAIL"}}, rows);
}

std::string format_event(const json& event) {
  const json job = event.is_object() && event.contains("job") ? event["job"] : json::object();
  // The event's own time: a progress step leaves the job's "updated" at its last state change.
  std::string when = local_time(text(event, "at"));
  if (when.empty()) {
    std::time_t now = std::time(nullptr);
    std::tm local{};
    localtime_r(&now, &local);
    char buf[32];
    std::strftime(buf, sizeof(buf), "%Y-%m-%d %H:%M:%S", &local);
    when = buf;
  }
  std::string from = text(event, "from");
  if (event.is_object() && event.value("progress", false)) {
    // Progress within a state (a knitted row): no arrow, just where the job is.
    return when + " job " + text(job, "id") + " " + text(job, "name") + ": " + text(event, "to") + ", " +
           text(event, "reason") + "\n";
  }
  std::string line = when + " job " + text(job, "id") + " " + text(job, "name") + ": " +
                     (from.empty() ? "(new)" : from) + " -> " + text(event, "to");
  std::string reason = text(event, "reason");
  if (!reason.empty()) line += " (" + reason + ")";
  return line + "\n";
}

std::string format_job_line(const json& job) {
  if (!job.is_object() || !job.contains("id")) return format_value(job);
  std::string line = "job " + text(job, "id") + " " + text(job, "name") + ": " +
                     text(job, "state");
  const std::string effect = text(job, "effect");
  std::string reason = text(job, "reason");
  if (!effect.empty()) {
    line += ", " + effect;  // what the command set under way, not shown by the reason yet
  } else if (!reason.empty()) {
    line += " (" + reason + ")";
  }
  return line + "\n";
}

std::string list_cut_note(const json& result) {
  if (!result.is_object() || !result.contains("jobs") || !result["jobs"].is_array() ||
      !result.contains("total") || !result["total"].is_number_integer()) {
    return "";
  }
  const auto shown = static_cast<long long>(result["jobs"].size());
  const auto total = result["total"].get<long long>();
  if (shown >= total) return "";
  return "showing " + std::to_string(shown) + " of " + std::to_string(total) +
         " jobs; --all for every job\n";
}

std::string format_cancel_all(const json& result) {
  if (!result.is_object() || !result.contains("jobs")) return format_value(result);
  std::string out;
  for (const json& job : result["jobs"]) out += format_job_line(job);
  const long long n = result.value("canceled", 0LL);
  if (n == 0) return out + "no unfinished jobs to cancel\n";
  out += "canceled " + std::to_string(n) + (n == 1 ? " job" : " jobs");
  const long long stopping = result.value("stopping", 0LL);
  if (stopping > 0) out += " (" + std::to_string(stopping) + " still stopping)";
  return out + "\n";
}

std::string format_value(const json& value) {
  if (value.is_null()) return "";
  if (value.is_string()) return value.get<std::string>() + "\n";
  if (value.is_object()) return scalar_lines(value, {}, {});
  if (value.is_array() && !value.empty() && value.front().is_object()) {
    // Columns are the first object's keys; later objects fill what they have.
    std::vector<Column> columns;
    std::vector<std::string> keys;
    for (const auto& [key, unused] : value.front().items()) {
      keys.push_back(key);
      std::string title = key;
      for (char& c : title) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
      columns.push_back({title});
    }
    std::vector<std::vector<std::string>> rows;
    for (const json& item : value) {
      std::vector<std::string> row;
      for (const auto& key : keys) row.push_back(text(item, key.c_str()));
      rows.push_back(std::move(row));
    }
    return table(columns, rows);
  }
  return dump(value) + "\n";
}

}  // namespace atelier::ctl

namespace atelier::ctl {
namespace {

std::string fixed(double v, int decimals) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

double number(const json& o, const char* key) {
  return o.is_object() && o.contains(key) && o[key].is_number() ? o[key].get<double>() : 0.0;
}

}  // namespace

std::string format_wood(const json& result) {
  if (!result.is_object() || !result.contains("sheets")) return format_value(result);
  std::string out;
  if (result.contains("done")) out += text(result, "done") + "\n";
  const json& sheets = result["sheets"];
  if (!sheets.is_array() || sheets.empty()) return out + "no veneer sheets\n";
  std::vector<std::vector<std::string>> rows;
  for (const json& s : sheets) {
    std::string size = "-";
    if (s.contains("size_mm") && s["size_mm"].is_array() && s["size_mm"].size() == 2)
      size = fixed(s["size_mm"][0].get<double>(), 0) + "x" + fixed(s["size_mm"][1].get<double>(), 0);
    std::string jobs;
    if (s.contains("jobs") && s["jobs"].is_array())
      for (const json& j : s["jobs"]) jobs += (jobs.empty() ? "" : ",") + (j.is_string() ? j.get<std::string>() : j.dump());
    rows.push_back({text(s, "id"), size, fixed(number(s, "dpi"), 1), fixed(number(s, "used_pct"), 1) + " %",
                    fixed(number(s, "free_mm2"), 0), text(s, "pieces"), or_dash(jobs)});
  }
  return out + table({{"ID"}, {"SIZE_MM"}, {"DPI"}, {"USED"}, {"FREE_MM2"}, {"PIECES"}, {"JOBS"}}, rows);
}

std::string format_laser(const nlohmann::json& result) {
  std::string out;
  auto reply_lines = [&out](const std::string& reply) {
    size_t from = 0;
    while (from <= reply.size() && !reply.empty()) {
      const size_t end = reply.find('\n', from);
      out += "  " + reply.substr(from, end == std::string::npos ? std::string::npos : end - from) + "\n";
      if (end == std::string::npos) break;
      from = end + 1;
    }
  };
  const nlohmann::json lines = result.is_object() ? result.value("lines", nlohmann::json::array()) : nlohmann::json();
  if (result.is_object() && result.contains("effect")) {
    for (const auto& l : lines) {
      if (!l.is_object()) continue;
      out += "> " + text(l, "sent") + "\n";
      for (const auto& r : l.value("reply", nlohmann::json::array()))
        if (r.is_string()) out += "  " + r.get<std::string>() + "\n";
    }
    out += text(result, "device") + ": " + text(result, "effect") + "\n";
    return out;
  }
  if (!lines.is_array() || lines.empty()) return "no console lines\n";
  for (const auto& l : lines) {
    if (!l.is_object()) continue;
    const std::string at = l.contains("at") ? local_time(text(l, "at")) : "";
    const std::string uid = l.contains("uid") ? l["uid"].dump() : "?";
    out += at + "  " + text(l, "device") + "  uid " + uid + "> " + text(l, "line") + "\n";
    reply_lines(text(l, "reply"));
  }
  return out;
}

}  // namespace atelier::ctl
