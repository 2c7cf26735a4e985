// A laser cutter behind GRBL 1.1 (drivers/grbl/): runs the G-code of `ready` laser jobs (kinds
// whose machine input is G-code, convert/kinds.h), and the operator's commands outside jobs
// (`atelierctl laser unlock|home|jog|origin|send`), on its worker thread, which alone opens the
// port. Every line such a command sends is logged with its reply in the store's console log.
//
// One connection, kept: the port is opened on first need and stays open across jobs, frames
// and commands (as LightBurn and OctoPrint keep theirs), since a board with a DTR auto-reset
// (an Uno) restarts when the port is reopened, losing an alarm lock and the head's position
// between a cancel and `laser unlock`, or a jog and a job started from here. Each reuse is
// re-checked without a reset (Session::revalidate); a link that proves dead then is opened
// anew once. It is dropped on a lost link, a silent controller or any unexpected error, when
// the port resolves elsewhere or the device goes offline, and closed on stop().
//
// Placement (contract B, drivers/grbl/machine_space.h): a job's G-code is in bed coordinates;
// its sidecar's `[laser] start_from` or `atelierctl start ID --start-from` (bed | origin | here)
// says where its (0,0) lands. The job is checked against the machine's space before anything
// is sent, the placement lines (G92 ...) go first and G92.1 after; the history records it.
//
// Safety first: a laser job only starts when an operator says so (`atelierctl start ID`),
// unless the device has autostart = true; it is never resumed or restarted on its own, after a
// crash, a daemon stop or a reconnect (the job becomes `interrupted` and needs `retry`).
// Life of a job here: ready -> running (connection checked or opened: $I, $$ and $# read, the job checked
// against $30 and the travel limits before anything is sent, optionally dry-run in check mode,
// then streamed) -> completed | canceled (feed hold, soft reset, M5) | failed (G-code error,
// ALARM, laser mode off, outside the travel) | interrupted (link lost, controller silent,
// daemon stopped).
// Progress is the share of G-code lines acknowledged; the device's detail adds the time left.
//
// Threading: one worker thread (DeviceWorker); public methods are thread-safe.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <optional>

#include <future>
#include <map>

#include <vector>

#include "daemon/device_worker.h"
#include "drivers/grbl/machine_space.h"
#include "drivers/grbl/session.h"
#include "drivers/transport.h"

namespace atelier {

struct LaserOptions {
  bool check_first = false;                 // [laser] check_first: dry run in GRBL check mode
  grbl::StartFrom start_from = grbl::StartFrom::bed;  // [laser] start_from: where jobs' (0,0) lands
  grbl::StreamMode mode = grbl::StreamMode::character_counting;
  double frame_feed_mm_min = 3000;          // speed of the beam-off outline trace
  grbl::Timeouts timeouts;
};

class LaserDevice : public DeviceWorker {
 public:
  using Opener = std::function<std::unique_ptr<Transport>(const std::string& port)>;

  // `clock`: the sessions' timeouts, the progress throttling and the job's run time, and the
  // worker's waits (see DeviceWorker).
  LaserDevice(DeviceConfig config, JobService& jobs, Opener open, PortResolver resolve,
              LaserOptions options = {}, Clock& clock = real_clock());
  ~LaserDevice() override;
  // Stops the worker (DeviceWorker::stop), then closes the kept connection.
  void stop() override;

  // `from_row` must be 0: ends a program pause (M0, e.g. a sheet swap) of the running job, or
  // releases a feed hold on it.
  void resume(int64_t job_id, int from_row) override;
  void hold(int64_t job_id) override;
  // Keeps `--start-from` for the job (checked here: BadInput for other options or values).
  void accept_start(const Job& job, const StartOptions& options) override;
  // Queues `cmd` for the worker and waits for it (see Device::machine_command).
  nlohmann::json machine_command(const MachineCommand& cmd) override;
  // Queues a beam-off trace of a ready job's bounds; the worker runs it when idle. Throws if
  // the job is not a ready job of this device or the laser is busy.
  void frame(int64_t job_id) override;

  // The G-code file a converted job of `kind` left in its output folder.
  static std::string gcode_file_for(const std::string& kind);

 private:
  bool run_next() override;
  // Adds the running job's "time_left_s" (seconds, from the last progress report) to "job".
  void describe_more(nlohmann::json& out) const override;
  bool cancel_running(int64_t job_id) override;
  void abort_running() override;
  void forget_requests() override;
  void run_job(int64_t id);
  // "held at line 27 of 115: feed hold, beam off; `atelierctl resume ID` continues"
  static std::string held_text(int64_t job_id, size_t acked, size_t total);
  // The job's start keys (sidecar [laser] and `--start-from`) with the device's defaults.
  struct JobPlacement {
    grbl::StartFrom from = grbl::StartFrom::bed;
    bool check_first = false;
  };
  JobPlacement placement_for(int64_t id);
  // Checks the job against the machine's space for `from` and sends the placement lines;
  // returns what was done, for the history ("start from bed: G92X400Y300"). Throws SetupError
  // (nothing sent) when the job does not fit.
  std::string place_job(grbl::Session& session, const grbl::MachineInfo& info, const grbl::Bounds* bounds,
                        grbl::StartFrom from, const std::string& file);
  // A queued operator command and the promise of its answer.
  struct MachineRequest;
  void run_machine_command(MachineRequest& req);
  // How a job that threw `e` ends and why, in the operator's words; `at` is "at line N of M",
  // `beam_may_fire` whether the real run had started sending. A lost link also marks the
  // device offline.
  struct Ending {
    JobState state;
    std::string reason;
  };
  Ending ending_for(const Error& e, int64_t id, const std::string& at, bool beam_may_fire);
  void run_frame(int64_t id);
  // The kept connection to the controller (worker thread only; see the header's top).
  struct Link {
    std::string port;                       // as resolved when it was opened
    std::unique_ptr<Transport> transport;   // outlives the session that reads it
    std::unique_ptr<grbl::Session> session;
    grbl::MachineInfo info;                 // as of the last connect or revalidate
  };
  // The connection, checked for this use: the kept one revalidated, or (none kept, the port
  // moved, or the kept one proved dead) the port opened and connected. Throws LinkLost,
  // grbl::SetupError or grbl::Silent, with no connection kept.
  Link& link();
  // Closes and forgets the kept connection, if any.
  void drop_link() noexcept;
  // After `e` ended a job, frame or command: keeps the connection when `e` leaves it in a
  // known state (a cancel, a refused line, an alarm, a check of ours), else drops it.
  void after_failure(const std::exception& e) noexcept;
  // A job's G-code on the connected controller, checked against it ($30, travel).
  struct Connection {
    grbl::Session& session;  // the kept link's
    grbl::MachineInfo info;
    grbl::Program program;
  };
  // Reads the job's G-code, connects (link()) and checks the job.
  // Throws LinkLost, grbl::SetupError (nothing sent) or std::runtime_error (unreadable file).
  Connection connect_for(int64_t id);

  Opener open_;
  LaserOptions options_;
  std::unique_ptr<Link> link_;  // the kept connection (worker thread; after the join, stop())

  // Guarded by mu_ (DeviceWorker's).
  std::shared_ptr<grbl::Controls> controls_;  // of the job or frame on the machine
  std::optional<int64_t> frame_request_;
  std::shared_ptr<MachineRequest> machine_request_;  // queued or being run; one at a time
  std::map<int64_t, grbl::StartFrom> start_from_;    // `--start-from` of armed jobs
  std::vector<int> source_lines_;  // the running job's Program::source_line (worker thread only)
  size_t acked_ = 0, total_ = 0;  // the running job's lines acknowledged / in it (for hold)
  bool framing_ = false;  // the job on the machine is being framed, not run
  bool paused_ = false;   // the job on the machine waits at a program pause (M0)
  double seconds_left_ = -1;  // the running job's estimate at its last progress report; -1: none yet
};

}  // namespace atelier
