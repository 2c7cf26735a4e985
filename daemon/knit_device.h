// A Brother knitting machine behind AYAB (drivers/ayab/): knits `ready` knit and lace jobs
// (the kinds in its config) row by row.
//
// A knit job is pattern.png (drivers/ayab/knit_plan.h); a lace job is chart.json of its output
// folder (convert/lace/lace_chart_json.h) planned for the lace carriage
// (drivers/ayab/lace_plan.h). A chart the lace carriage cannot do fails before the port is
// opened: "the lace carriage cannot knit this chart: <first problem>[; N more in report.json]".
// Rows are what the knitter counts: pattern rows for knit, chart rows (repeats_high included)
// for lace, whose progress also names the carriage the next pass needs.
//
// Life of a job here: ready -> running (planned onto the needle bed, session
// opened, rows sent as the carriage asks) -> completed | canceled (stopped after the current
// row with the blank last line, so the machine ends clean; a lace job after the current chart
// row's last pass, its transfers and both knit rows) | interrupted (link lost or machine
// silent: "device disconnected after row N"; `resume --from-row` continues; a lace chart row
// stopped between its passes is named, as its stitches may be moved but not knitted) | failed (the
// pattern does not fit, the firmware is too old, ...).
// What the knitter should do is the running job's reason and the device's detail, in order:
// "move the carriage over the left turn mark (set it to KC-I or KC-II)" (the board resets when
// the port opens), "knitting row N of M" (lace: "knitting chart row N of M; next: lace
// carriage"), "all M rows knitted; one more pass to finish: ..." (the blank last line's pass,
// waited for), then completed.
// A row the session cannot vouch for (ayab::LineGarbled: its line reached the firmware garbled,
// or the carriage was on the needles before the line arrived) interrupts the job: "row N was
// knitted from a line garbled on the cable ...: stop the carriage, unravel that row, then continue
// with: atelierctl resume ID --from-row N" - the row is not counted. A board that stops
// answering (ayab::MachineSilent; firmware 1.0 hangs on a garbled SLIP escape) is reset through
// DTR and the job interrupted: "... stopped answering after row N (...); atelier reset it;
// continue with: ..." ("... still does not answer: unplug it and plug it back" when the reset
// did not help); hung before knitting started, it is reset once and the job goes on.
// A board that refuses to start in the wrong state (not reset when the port opened, e.g. still
// knitting for a daemon that was killed, on a board whose DTR auto-reset is disabled) is reset
// once through DTR (Transport::pulse_dtr) and the handshake repeated; refused again, the job
// fails within seconds: "<device>: the knitting machine refused to start: <error and state>;
// reset it ... and retry the job".
// Online/offline: the port is watched while idle (its device node exists, or the USB device
// maps to a tty); it is only opened for a job, since opening resets an Arduino.
//
// Threading: one worker thread (DeviceWorker); public methods are thread-safe.
#pragma once

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "daemon/device_worker.h"
#include "daemon/job_service.h"
#include "drivers/ayab/host_session.h"
#include "drivers/transport.h"

namespace atelier {

class KnitDevice : public DeviceWorker {
 public:
  // Opens a transport to a port path (SerialTransport::open in the daemon, fakes in tests).
  using Opener = std::function<std::unique_ptr<Transport>(const std::string& port)>;

  // `clock`: the sessions' deadlines and the worker's waits (see DeviceWorker).
  KnitDevice(DeviceConfig config, JobService& jobs, Opener open, PortResolver resolve,
             ayab::SessionTimeouts timeouts = {}, Clock& clock = real_clock());
  ~KnitDevice() override;

  void resume(int64_t job_id, int from_row) override;
  // The device's autostart, or the job's own `autostart = true` (its sidecar or job file).
  bool autostarts(const Job& job) const override;

 private:
  // Where a job begins: its row and the needle of its leftmost stitch.
  struct ChosenStart {
    int from_row = 1;                 // 1-based, in knitting order
    std::optional<int> start_needle;  // 0-based; none: the device's start_needle, or centred
    std::string text;                 // "from row 5, needles L20 to R39"; "" for the defaults
  };
  struct Work {
    int64_t id;
    int from_row;  // 1-based pattern row to start at
    std::optional<int> start_needle;  // 0-based leftmost needle; none: plan_params()'s
    std::string refused;              // non-empty: the job's start cannot be (fail it)
  };
  // `atelierctl start` options over the job's own keys (convert/common/job_start.h), checked
  // against its plan; `check_row` false ignores the row (a resume names its own). Throws
  // BadInput naming the values (untagged: each caller says whose job it is): a row outside
  // the pattern, a needle that is not on the bed or puts the pattern off it, an unreadable
  // sidecar; CannotPlan (a BadInput) when the job cannot be planned at all.
  ChosenStart choose_start(const Job& job, const StartOptions& options, bool check_row = true) const;
  void accept_start(const Job& job, const StartOptions& options) override;
  void forget_requests() override { starts_.clear(); }
  bool run_next() override;
  bool cancel_running(int64_t job_id) override;
  void abort_running() override;
  void describe_more(nlohmann::json& out) const override { out["machine"] = config_.machine; }
  // Picks the next job (a resume first, then a ready one) and marks it running.
  std::optional<Work> next_work();
  void knit(const Work& work);
  // The job stopped on purpose (cancel, or the daemon stopping): canceled, or interrupted
  // when the daemon stops (so it is never resumed without an operator).
  void end_early(int64_t id, int rows_done, bool knitting_started, const std::string& in_progress = "");
  ayab::PlanParams plan_params(std::optional<int> start_needle = std::nullopt) const;
  // What the job knits: its passes and where each row (counted from 0) starts.
  struct JobPlan {
    ayab::KnitPlan plan;
    std::vector<int> row_start;  // first pass of each row, then passes.size()
    int rows() const { return static_cast<int>(row_start.size()) - 1; }
  };
  // Throws std::runtime_error: unreadable input, a pattern that does not fit, a lace chart
  // the lace carriage cannot do (then the message is the job's whole failure reason).
  JobPlan plan_job(const Job& job, std::optional<int> start_needle = std::nullopt) const;

  Opener open_;
  ayab::SessionTimeouts timeouts_;

  // Guarded by mu_ (DeviceWorker's).
  std::shared_ptr<std::atomic<bool>> cancel_flag_;
  // The open link while a job waits for the machine to become ready (a person has to move
  // the carriage, which may never happen): stop() and cancel() close it to end the wait.
  // Null while rows are being knitted: then cancel ends cleanly after the current row.
  Transport* waiting_link_ = nullptr;
  std::map<int64_t, int> resumes_;  // job -> from_row
  std::map<int64_t, ChosenStart> starts_;  // armed by `atelierctl start`: where each begins
  // The needle placement each job started with, so that a resume knits on the same needles.
  std::map<int64_t, std::optional<int>> placements_;
};

}  // namespace atelier
