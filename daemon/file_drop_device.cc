#include "daemon/file_drop_device.h"

#include <fstream>
#include <sstream>
#include <vector>

#include "base/error.h"
#include "convert/kinds.h"

namespace atelier {
namespace fs = std::filesystem;

namespace {

std::string read_whole(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw BadInput(file.filename().string() + " cannot be read");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

// design.<format> for a job of `kind` (its registry entry names the stem).
std::string stitch_file_name(const std::string& kind, const std::string& format) {
  const KindInfo* k = find_kind(kind);
  if (!k || k->machine_input != MachineInput::stitch_files)
    throw BadInput("a file-drop device cannot deliver '" + kind + "' jobs (they make no stitch file)");
  return std::string(k->machine_file) + "." + format;
}

}  // namespace

FileDropDevice::FileDropDevice(DeviceConfig config, JobService& jobs, FolderOpener open, Clock& clock)
    : DeviceWorker(
          std::move(config), jobs,
          [this]() -> std::optional<std::string> {
            return config_.dir;  // always reachable; a missing folder fails the job with its reason
          },
          clock),
      open_(open ? std::move(open) : [](const fs::path& dir) -> std::unique_ptr<DropFolder> {
        return std::make_unique<PosixDropFolder>(dir);
      }) {}

FileDropDevice::~FileDropDevice() { stop(); }

void FileDropDevice::resume(int64_t job_id, int) {
  throw BadInput(job_tag(job_id) + ": " + config_.name +
                           " only writes files; there is nothing to resume (`atelierctl retry " +
                           std::to_string(job_id) + "` delivers a failed job again)");
}

std::string FileDropDevice::file_name(int64_t id, const std::string& input_name,
                                      const std::string& format) {
  std::string stem;
  for (char c : fs::path(input_name).stem().string()) {
    if (stem.size() >= 24) break;
    const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                       c == '-' || c == '_';
    stem += plain ? c : '_';
  }
  return std::to_string(id) + (stem.empty() ? "" : "-" + stem) + "." + format;
}

bool FileDropDevice::run_next() {
  // Looked at here, on the worker thread, so describe() never waits on a hung mount.
  folder_present_ = open_(config_.dir)->present();
  auto id = claim_ready("writing to " + config_.dir);
  if (!id) return false;
  try {
    deliver(*id);
  } catch (const std::exception& e) {  // the store failed under us: never leave it running
    jobs_.transition(*id, JobState::failed, config_.name + ": " + e.what());
  }
  return true;
}

void FileDropDevice::deliver(int64_t id) {
  auto job = jobs_.store().get(id);
  if (!job) return;
  std::unique_ptr<DropFolder> folder;
  std::vector<std::string> written;
  try {
    folder = open_(config_.dir);
    if (!folder->present())
      throw DropError(config_.dir + " is missing (is the stick mounted?)", ENOENT);
    for (const std::string& format : config_.formats) {
      const std::string design = stitch_file_name(job->kind, format);
      const fs::path source = fs::path(job->output_dir) / design;
      if (!fs::exists(source))
        throw BadInput("the conversion made no " + design + " for " + config_.name);
      const std::string name = file_name(id, job->name, format);
      folder->write_atomically(name, read_whole(source));
      written.push_back(name);
    }
  } catch (const std::exception& e) {
    for (const std::string& name : written) folder->remove(name);
    jobs_.transition(id, JobState::failed,
                     config_.name + ": " + e.what() + "; nothing was left in the folder and the design "
                     "stays in done/" + std::to_string(id) + " (`atelierctl retry " +
                     std::to_string(id) + "` converts and delivers it again)");
    set_last("job " + std::to_string(id) + " failed: " + e.what());
    return;
  }
  std::string list;
  for (const std::string& name : written) list += (list.empty() ? "" : ", ") + name;
  jobs_.transition(id, JobState::completed, "written to " + config_.dir + ": " + list);
  set_last("job " + std::to_string(id) + " written: " + list);
}

void FileDropDevice::describe_more(nlohmann::json& out) const {
  out["dir"] = config_.dir;
  out["formats"] = config_.formats;
  out["folder"] = folder_present_ ? "present" : "missing";
}

}  // namespace atelier
