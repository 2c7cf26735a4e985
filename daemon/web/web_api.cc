// WebServer: the job endpoints of the JSON API (docs/web.md): the list, one job, its files,
// the actions and uploads. Each maps onto a control verb (Daemon::handle), so the page can do
// exactly what atelierctl can, with the same checks and messages.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <httplib.h>
#include <memory>

#include "base/unique_fd.h"
#include "daemon/log.h"
#include "daemon/web/http_reply.h"
#include "daemon/web/job_files.h"
#include "daemon/web/job_timing.h"
#include "daemon/web/web_server.h"

namespace atelier::web {
namespace {

constexpr int64_t kDefaultPage = 50;
constexpr int64_t kMaxPage = 200;
constexpr size_t kMaxFieldBytes = 65536;  // a form field other than the file (a --set value)

int64_t match_id(const httplib::Request& req) { return std::stoll(req.matches[1].str()); }

// A non-negative integer query parameter, or `fallback`; nullopt if it is not one.
std::optional<int64_t> int_param(const httplib::Request& req, const char* name, int64_t fallback) {
  if (!req.has_param(name)) return fallback;
  const std::string v = req.get_param_value(name);
  if (v.empty() || v.size() > 12 || !std::all_of(v.begin(), v.end(), [](unsigned char c) { return std::isdigit(c); }))
    return std::nullopt;
  return std::stoll(v);
}

// A control error as an HTTP status: an unknown job is 404, anything else `otherwise` (409 for
// an action the job's or the machine's state does not allow, 400 for a request that is wrong).
int status_of(const ControlError& e, int otherwise) {
  return std::string(e.what()).rfind("no job ", 0) == 0 ? 404 : otherwise;
}

// A file name for the job: the last component of what the browser sent, without control
// characters (they would only garble the list).
std::string upload_name(const std::string& filename) {
  std::string name = filename.substr(filename.find_last_of("/\\") == std::string::npos ? 0 : filename.find_last_of("/\\") + 1);
  name.erase(std::remove_if(name.begin(), name.end(), [](unsigned char c) { return c < 0x20 || c == 0x7f; }), name.end());
  return name == "." || name == ".." ? "" : name;
}

// An unnamed file in the spool's filesystem for an upload as it arrives (O_TMPFILE: it never
// has a name, so nothing is left behind whatever happens). The spool, not /tmp: it is where
// the job is copied to next, and the unit's PrivateTmp= may be small.
UniqueFd upload_file(const std::filesystem::path& spool) {
  UniqueFd fd(::open(spool.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600));
  if (fd.valid()) return fd;
  std::string name = (spool / ".web-upload-XXXXXX").string();
  fd.reset(::mkostemp(name.data(), O_CLOEXEC));
  if (fd.valid()) ::unlink(name.c_str());
  return fd;
}

bool write_all(int fd, const char* data, size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(fd, data, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += w;
    n -= static_cast<size_t>(w);
  }
  return true;
}

// "name" for a Content-Disposition header: the characters that could end or break it dropped.
std::string disposition_name(const std::string& name) {
  std::string out;
  for (unsigned char c : name)
    if (c >= 0x20 && c < 0x7f && c != '"' && c != '\\') out.push_back(static_cast<char>(c));
  return out.empty() ? "file" : out;
}

}  // namespace

nlohmann::json WebServer::with_timing(nlohmann::json job) {
  const int64_t id = job.value("id", int64_t{0});
  std::optional<Job> stored = backend_.store->get(id);
  if (!stored) return job;
  std::optional<int64_t> since;
  if (is_active(stored->state)) {
    const std::string state = state_name(stored->state);
    for (const JobEvent& e : backend_.store->history(id))
      if (e.to == state && e.from != state) since = e.at_ms;
  }
  std::optional<double> device_left;
  {
    std::lock_guard lock(mu_);
    for (const auto& d : devices_) {
      const auto& on = d.contains("job") ? d["job"] : nlohmann::json();
      if (on.is_object() && on.value("id", int64_t{0}) == id && on.contains("time_left_s") &&
          on["time_left_s"].is_number())
        device_left = on["time_left_s"].get<double>();
    }
  }
  const JobTiming t = job_timing(*stored, since, now_ms(), device_left);
  job["elapsed_s"] = t.elapsed_s;
  job["state_s"] = t.state_s ? nlohmann::json(*t.state_s) : nlohmann::json(nullptr);
  job["time_left_s"] = t.time_left_s ? nlohmann::json(*t.time_left_s) : nlohmann::json(nullptr);
  return job;
}

void WebServer::serve_jobs(const httplib::Request& req, httplib::Response& res) {
  nlohmann::json args = nlohmann::json::object();
  if (req.has_param("state") && !req.get_param_value("state").empty()) args["state"] = req.get_param_value("state");
  if (req.has_param("kind") && !req.get_param_value("kind").empty()) args["kind"] = req.get_param_value("kind");
  const auto limit = int_param(req, "limit", kDefaultPage);
  const auto offset = int_param(req, "offset", 0);
  if (!limit || *limit < 1 || *limit > kMaxPage) {
    json_error(res, 400, "limit must be a whole number from 1 to " + std::to_string(kMaxPage));
    return;
  }
  if (!offset) {
    json_error(res, 400, "offset must be a whole number >= 0 (jobs to skip, newest first)");
    return;
  }
  args["limit"] = *limit;
  args["offset"] = *offset;
  nlohmann::json result;
  try {
    result = call("list", args);
  } catch (const ControlError& e) {
    json_error(res, 400, e.what());
    return;
  }
  nlohmann::json jobs = nlohmann::json::array();
  for (auto& j : result["jobs"]) jobs.push_back(with_timing(std::move(j)));
  reply_json(res, 200, {{"jobs", jobs}, {"total", result["total"]}, {"offset", *offset}, {"limit", *limit}});
}

void WebServer::serve_job(const httplib::Request& req, httplib::Response& res) {
  nlohmann::json job;
  try {
    job = call("show", {{"id", match_id(req)}});
  } catch (const ControlError& e) {
    json_error(res, status_of(e, 400), e.what());
    return;
  }
  std::vector<std::string> outputs;
  for (const auto& o : job.value("outputs", nlohmann::json::array())) outputs.push_back(o.get<std::string>());
  job["previews"] = preview_files(job.value("kind", ""), outputs);
  reply_json(res, 200, with_timing(std::move(job)));
}

void WebServer::serve_file(const httplib::Request& req, httplib::Response& res) {
  const int64_t id = match_id(req);
  const std::string name = req.matches[2].str();
  std::optional<Job> job = backend_.store->get(id);
  std::optional<OpenedFile> file;
  if (job && !job->output_dir.empty()) file = open_job_file(backend_.config()->spool_dir, job->output_dir, name);
  if (!file) {
    // Whatever the reason (no job, a traversal, a symlink, no such file): the same answer.
    json_error(res, 404, "job " + std::to_string(id) + " has no output file by that name");
    return;
  }
  const bool download = req.get_param_value("download") == "1" || !shown_inline(name);
  res.set_header("Content-Disposition", std::string(download ? "attachment" : "inline") + "; filename=\"" +
                                            disposition_name(name) + "\"");
  // A user's SVG (a cut job's input) opened on its own must not run script in this origin.
  res.set_header("Content-Security-Policy", "default-src 'none'; img-src 'self' data:; style-src 'unsafe-inline'; sandbox");
  res.set_header("Cache-Control", "private, max-age=60");
  auto fd = std::make_shared<UniqueFd>(std::move(file->fd));
  res.set_content_provider(file->size, content_type_for(name),
                           [fd](size_t offset, size_t length, httplib::DataSink& sink) {
                             char buf[65536];
                             const ssize_t n = ::pread(fd->get(), buf, std::min(length, sizeof buf),
                                                       static_cast<off_t>(offset));
                             if (n <= 0) return false;  // the file shrank: end the response short
                             return sink.write(buf, static_cast<size_t>(n));
                           });
}

void WebServer::serve_action(const httplib::Request& req, httplib::Response& res) {
  std::string user;
  if (!allowed_to_act(req, res, user)) return;
  const int64_t id = match_id(req);
  const std::string verb = req.matches[2].str();
  nlohmann::json args = {{"id", id}};
  if (!req.body.empty()) {
    nlohmann::json body = nlohmann::json::parse(req.body, nullptr, false);
    if (!body.is_object()) {
      json_error(res, 400, verb + ": the body must be a JSON object (or empty)");
      return;
    }
    // Only what the verb takes from a person: never "all" (cancel every job) or other keys.
    std::vector<std::string> keys;
    if (verb == "start") keys = {"from_row", "start_needle", "start_from"};
    if (verb == "resume") keys = {"from_row"};
    for (const auto& [key, value] : body.items()) {
      if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
        json_error(res, 400, verb + " takes no \"" + key.substr(0, 40) + "\"");
        return;
      }
      args[key] = value;
    }
  }
  nlohmann::json result;
  try {
    result = call(verb, args);
  } catch (const ControlError& e) {
    json_error(res, status_of(e, 409), e.what());
    return;
  }
  log::Fields fields;
  fields.job_id = id;
  log::info("web: " + verb + " by " + user + " from " + req.remote_addr, fields);
  reply_json(res, 200, with_timing(std::move(result)));
}

void WebServer::serve_submit(const httplib::Request& req, httplib::Response& res, const httplib::ContentReader& reader) {
  std::string user;
  // Refused before the body is read. "Connection: close" asks the client to close its end:
  // httplib 0.11 itself would read the unread rest of the body as further requests (which
  // carry no credentials, so they are refused too).
  if (!allowed_to_act(req, res, user) || !req.is_multipart_form_data()) {
    if (res.status < 400) json_error(res, 400, "submit takes multipart/form-data: fields kind, file and any number of set");
    res.set_header("Connection", "close");
    return;
  }
  const auto config = backend_.config();
  const uint64_t max_bytes = config->limits.max_file_bytes;
  auto refuse_too_big = [&](const std::string& what) {
    json_error(res, 413, what + ": larger than the hot folder's limit of " + std::to_string(max_bytes) +
                             " bytes ([limits] max_file_bytes)");
    res.set_header("Connection", "close");  // the rest of the body is never read (see above)
  };
  // Announced larger than any file it may carry: refused before a byte is stored.
  if (req.get_header_value<uint64_t>("Content-Length") > max_bytes + kMaxJsonBody) {
    refuse_too_big("the upload");
    return;
  }
  UniqueFd file = upload_file(config->spool_dir);
  if (!file.valid()) {
    json_error(res, 500, std::string("cannot store the upload in the spool: ") + std::strerror(errno));
    return;
  }
  std::string field, value, kind, filename;
  std::vector<std::string> sets;
  bool has_file = false, too_big = false, write_failed = false, field_too_long = false;
  auto end_field = [&] {
    if (field == "kind") kind = value;
    else if (field == "set") sets.push_back(value);
    field.clear();
    value.clear();
  };
  uint64_t written = 0;
  const bool read = reader(
      [&](const httplib::MultipartFormData& part) {
        end_field();
        field = part.name;
        if (field == "file") {
          if (has_file) return false;  // one file a job
          has_file = true;
          filename = part.filename;
        }
        return true;
      },
      [&](const char* data, size_t n) {
        if (stopped_) return false;  // the daemon is stopping: it does not wait for the upload
        if (field == "file") {
          written += n;
          if (written > max_bytes) return !(too_big = true);
          if (!write_all(file.get(), data, n)) return !(write_failed = true);
          return true;
        }
        if (value.size() + n > kMaxFieldBytes) return !(field_too_long = true);
        value.append(data, n);
        return true;
      });
  end_field();
  if (too_big) {
    refuse_too_big(filename.empty() ? std::string("the upload") : upload_name(filename));
    return;
  }
  if (write_failed) {
    json_error(res, 507, "cannot store the upload in the spool: " + std::string(std::strerror(errno)));
    return;
  }
  if (field_too_long) {
    json_error(res, 400, "a form field other than the file is longer than " + std::to_string(kMaxFieldBytes) + " bytes");
    return;
  }
  if (!read) {
    json_error(res, 400, "the upload broke off or is not well-formed multipart/form-data");
    res.set_header("Connection", "close");
    return;
  }
  const std::string name = upload_name(filename);
  if (!has_file || name.empty()) {
    json_error(res, 400, "submit needs a file (the form field \"file\", with its file name)");
    return;
  }
  if (kind.empty()) {
    json_error(res, 400, name + ": submit needs a kind (the form field \"kind\")");
    return;
  }
  ::lseek(file.get(), 0, SEEK_SET);
  ControlRequest request;
  request.verb = "submit";
  request.args = {{"path", name}, {"kind", kind}, {"set", sets}};
  request.files.push_back(std::move(file));
  request.via = "the web page by " + user + " from " + req.remote_addr;
  nlohmann::json job;
  try {
    job = backend_.call(request);
  } catch (const ControlError& e) {
    json_error(res, 400, e.what());
    return;
  }
  log::Fields fields;
  fields.job_id = job.value("id", int64_t{0});
  fields.kind = kind;
  log::info("web: " + name + " (" + std::to_string(written) + " bytes) submitted by " + user + " from " +
                req.remote_addr,
            fields);
  reply_json(res, 201, with_timing(std::move(job)));
}

}  // namespace atelier::web
