// An embroidery machine (or any machine that reads files) fed through a drop folder, e.g. a USB
// stick mounted at /media/EMB or a network share: `[[device]] driver = "file-drop"
// dir = "/media/EMB" formats = ["dst", "exp"]`.
//
// Life of a job here: ready -> running -> completed (every format written, each atomically:
// drivers/file_drop/drop_folder.h) | failed (the folder is missing or full, or a format the
// conversion did not make). A failed delivery takes back the files it already wrote, so the
// folder never holds half a job; the job's outputs stay in done/<id> (nothing is lost) and
// `atelierctl retry ID` converts and delivers it again. An existing file of the same name is
// never replaced (it fails the job: e.g. a stick written by another atelier). Files are named "<id>-<stem>.<format>" (stem: the
// dropped file's name without extension, letters, digits, '-' and '_' only, at most 24), so
// two designs never overwrite each other and the machine's file list shows what they are.
// The device is always "online" (writing a file is safe and quick, so autostart defaults to
// true); describe() says whether the folder is there.
//
// Threading: one worker thread (DeviceWorker); public methods are thread-safe.
#pragma once

#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>

#include "daemon/device_worker.h"
#include "drivers/file_drop/drop_folder.h"

namespace atelier {

class FileDropDevice : public DeviceWorker {
 public:
  // Opens the device's folder (tests pass a fake that fails like a full stick).
  using FolderOpener = std::function<std::unique_ptr<DropFolder>(const std::filesystem::path&)>;

  // `clock`: the worker's waits (see DeviceWorker).
  FileDropDevice(DeviceConfig config, JobService& jobs, FolderOpener open = nullptr, Clock& clock = real_clock());
  ~FileDropDevice() override;

  // Nothing to resume: a delivery either happened or failed (then `retry`).
  void resume(int64_t job_id, int from_row) override;

  // "<id>-<stem>.<format>" for a job's file in the drop folder.
  static std::string file_name(int64_t id, const std::string& input_name, const std::string& format);

 private:
  bool run_next() override;
  // A delivery takes milliseconds and cannot be stopped half-way (it takes back its files).
  bool cancel_running(int64_t) override { return false; }
  void abort_running() override {}
  void describe_more(nlohmann::json& out) const override;
  void deliver(int64_t id);

  FolderOpener open_;
  std::atomic<bool> folder_present_{false};  // as the worker last saw it
};

}  // namespace atelier
