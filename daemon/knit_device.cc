#include "daemon/knit_device.h"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "base/error.h"
#include "convert/common/job_start.h"
#include "convert/common/param_table.h"
#include "convert/kinds.h"
#include "convert/knit/knit_order.h"
#include "convert/lace/lace_chart_json.h"
#include "convert/report_file.h"
#include "daemon/job_json.h"
#include "daemon/job_log.h"
#include "daemon/log.h"
#include "drivers/ayab/knit_plan.h"
#include "drivers/ayab/lace_plan.h"

namespace fs = std::filesystem;

namespace atelier {
namespace {

// DTR low this long resets an Arduino (its auto-reset takes the edge; avrdude and pyserial
// users hold it 50-250 ms).
constexpr std::chrono::milliseconds kDtrResetPulse{100};

// How the user continues a job that stopped after `rows_done` rows; `in_progress` is the
// note on a lace row stopped part way ("" when none was).
std::string resume_hint(int64_t id, int rows_done, const std::string& in_progress = "") {
  return in_progress + "continue with: atelierctl resume " + std::to_string(id) + " --from-row " +
         std::to_string(rows_done + 1);
}

// What the knitter is asked to do while the firmware waits for the carriage to pass a turn
// mark (AYAB desktop: "Please start machine. (Set the carriage to mode KC-I or KC-II and move
// the carriage over the left turn mark)."); a lace job may begin with the lace carriage.
std::string turn_mark_prompt(const ayab::KnitPlan& plan, int from_pass) {
  if (!plan.carriage.empty() && from_pass < static_cast<int>(plan.carriage.size()) &&
      plan.carriage[static_cast<size_t>(from_pass)] == ayab::Carriage::lace)
    return "move the lace carriage over the left turn mark";
  return "move the carriage over the left turn mark (set it to KC-I or KC-II)";
}

// A lace chart the lace carriage cannot knit; what() is the job's failure reason.
class CannotKnit : public BadInput {
 public:
  using BadInput::BadInput;
};

// The job cannot be planned at all (unreadable, wider than the bed, a chart the carriage
// cannot do), whatever its start: knit() fails it with the plan's own reason.
class CannotPlan : public BadInput {
 public:
  using BadInput::BadInput;
};

// Why a knit job's report says it is not knittable as is ("" when it is, or when the report
// predates "knittable"): an incomplete solution (solver "none", random-walk) holds floats
// longer than the limit, and the machine is not sent it.
std::string not_knittable_reason(const fs::path& output_dir) {
  const nlohmann::json r = read_report(output_dir);
  if (!r.is_object() || !r.contains("knittable") || r["knittable"] != false) return "";
  for (const std::string& line : report_warnings(r))
    if (line.rfind("not knittable", 0) == 0) return line;
  return "not knittable as is (the report says knittable false)";
}

// What the knitting machine is fed for a job of `kind`: a lace chart or a stitch pattern.
// BadInput for a kind no knitting machine knits.
const KindInfo& knitted_kind(const std::string& kind) {
  const KindInfo* k = find_kind(kind);
  if (!k || (k->machine_input != MachineInput::lace_chart && k->machine_input != MachineInput::knit_pattern))
    throw BadInput("a knitting machine cannot knit '" + kind + "' jobs");
  return *k;
}

bool is_lace(const std::string& kind) { return knitted_kind(kind).machine_input == MachineInput::lace_chart; }

LaceChartFile read_chart(const fs::path& dir, std::string_view file_name) {
  const fs::path file = dir / file_name;
  std::ifstream in(file);
  if (!in) throw BadInput(file.string() + " cannot be read");
  std::ostringstream text;
  text << in.rdbuf();
  return lace_chart_from_json_text(text.str(), file.string());
}

// The job's own start keys: its sidecar NAME.EXT.toml, or for a job-file kind (lace) the
// job file itself, in its output folder. None when there is no such file.
JobStart read_job_start(const Job& job) {
  // Still in work/<id>/ while its conversion ends (the scheduler asks what it waits for).
  const fs::path dir = job.output_dir.empty() ? fs::path(job.work_dir) : fs::path(job.output_dir);
  if (dir.empty()) return {};
  const fs::path file = converts_job_file(job.kind) ? dir / job.name : dir / (job.name + ".toml");
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return {};
  toml::table table;
  try {
    table = toml::parse_file(file.string());
  } catch (const toml::parse_error& e) {
    throw BadInput(toml_error_text(e, file.string()));
  }
  return take_job_start(table, file.string());
}

}  // namespace

bool KnitDevice::autostarts(const Job& job) const {
  if (config_.autostart) return true;
  try {
    return read_job_start(job).autostart.value_or(false);
  } catch (const std::exception&) {
    return false;  // a sidecar that no longer reads: the knitter starts it (and hears why)
  }
}

KnitDevice::ChosenStart KnitDevice::choose_start(const Job& job, const StartOptions& options,
                                                 bool check_row) const {
  const JobStart own = read_job_start(job);
  ChosenStart out;
  const ayab::MachineType machine = *ayab::machine_from_name(config_.machine);
  const int needles = ayab::needle_count(machine);
  const std::optional<std::string> needle_text = options.start_needle ? options.start_needle : own.start_needle;
  const std::string needle_from = options.start_needle ? "--start-needle " : "start_needle ";
  if (needle_text) {
    std::string problem;
    out.start_needle = parse_bed_needle(*needle_text, needles, &problem);
    if (!out.start_needle)
      throw BadInput(needle_from + *needle_text + " is not a needle of the " + config_.machine +
                     " (" + config_.name + "): " + problem);
  }
  JobPlan sized;  // at needle 0 (fits whenever the pattern is not wider than the bed): rows, width
  try {
    sized = plan_job(job, 0);
  } catch (const std::exception& e) {
    throw CannotPlan(e.what());
  }
  const bool lace = is_lace(job.kind);
  const int rows = sized.rows();
  const std::optional<int> row = options.from_row ? options.from_row : own.start_row;
  const std::string row_from = options.from_row ? "--from-row " : "start_row ";
  if (check_row && row) {
    if (*row < 1 || *row > rows)
      throw BadInput(row_from + std::to_string(*row) + " is outside the " +
                     (lace ? "chart" : "pattern") + " (rows 1 to " + std::to_string(rows) + ")");
    out.from_row = *row;
  }
  const int width = sized.plan.stop_needle - sized.plan.start_needle + 1;
  if (out.start_needle && *out.start_needle + width > needles) {
    const int last = needles - width;  // the rightmost needle the pattern may start on
    throw BadInput(needle_from + *needle_text + " puts the " + (lace ? "lace's " : "pattern's ") +
                   std::to_string(width) + " stitches on needles " + bed_needle_name(*out.start_needle, needles) +
                   " to " + bed_needle_name(*out.start_needle + width - 1, needles) + ", off the " +
                   config_.machine + "'s bed (" + bed_needle_name(0, needles) + " to " +
                   bed_needle_name(needles - 1, needles) + "); start it on " + bed_needle_name(0, needles) +
                   " to " + bed_needle_name(last, needles));
  }
  if (out.from_row > 1) out.text = "from " + std::string(lace ? "chart row " : "row ") + std::to_string(out.from_row);
  if (out.start_needle)
    out.text += (out.text.empty() ? "" : ", ") + std::string("needles ") + bed_needle_name(*out.start_needle, needles) +
                " to " + bed_needle_name(*out.start_needle + width - 1, needles);
  return out;
}

void KnitDevice::accept_start(const Job& job, const StartOptions& options) {
  ChosenStart chosen;
  try {
    chosen = choose_start(job, options);
  } catch (const CannotPlan&) {
    // Armed all the same: knit() fails it before the port opens, with the plan's reason.
  } catch (const std::exception& e) {
    throw BadInput(job_tag(job.id) + ": " + e.what());
  }
  std::lock_guard lock(mu_);
  starts_[job.id] = std::move(chosen);
}

KnitDevice::JobPlan KnitDevice::plan_job(const Job& job, std::optional<int> start_needle) const {
  JobPlan out;
  const KindInfo& kind = knitted_kind(job.kind);
  if (kind.machine_input == MachineInput::lace_chart) {
    const LaceChartFile chart = read_chart(job.output_dir, kind.machine_file);
    ayab::LacePlanResult res =
        ayab::plan_lace(chart.chart, chart.cast_on, chart.repeats_wide, chart.repeats_high, plan_params(start_needle));
    if (!res.plan) {
      std::string why = "the lace carriage cannot knit this chart: " + res.problems.front();
      if (res.problems.size() > 1) why += "; " + std::to_string(res.problems.size() - 1) + " more in report.json";
      throw CannotKnit(why);
    }
    out.plan = std::move(*res.plan);
    // pattern_row is the chart row of each pass, non-decreasing from 0.
    const auto& rows = out.plan.pattern_row;
    for (size_t p = 0; p < rows.size(); ++p)
      if (p == 0 || rows[p] != rows[p - 1]) out.row_start.push_back(static_cast<int>(p));
  } else {
    if (const std::string why = not_knittable_reason(job.output_dir); !why.empty())
      throw CannotKnit("refused: " + why + "; convert it again with a complete solver");
    const fs::path file = fs::path(job.output_dir) / kind.machine_file;
    cv::Mat image = cv::imread(file.string(), cv::IMREAD_GRAYSCALE);
    if (image.empty()) throw BadInput(file.string() + " cannot be read");
    cv::Mat pattern = image < 128;  // black = contrast = 1
    pattern /= 255;
    ayab::PlanParams params = plan_params(start_needle);
    params.first_row_top = job_knits_top_row_first(job.output_dir);  // as its chart.pdf says
    out.plan = ayab::plan_knitting(pattern, params);
    for (int r = 0; r < pattern.rows; ++r) out.row_start.push_back(r * out.plan.passes_per_row);
  }
  out.row_start.push_back(static_cast<int>(out.plan.passes.size()));
  return out;
}

KnitDevice::KnitDevice(DeviceConfig config, JobService& jobs, Opener open, PortResolver resolve,
                       ayab::SessionTimeouts timeouts, Clock& clock)
    : DeviceWorker(std::move(config), jobs, std::move(resolve), clock),
      open_(std::move(open)),
      timeouts_(timeouts) {}

KnitDevice::~KnitDevice() { stop(); }

void KnitDevice::abort_running() {
  if (cancel_flag_) cancel_flag_->store(true);
  if (waiting_link_) waiting_link_->close();
}

bool KnitDevice::cancel_running(int64_t job_id) {
  resumes_.erase(job_id);
  starts_.erase(job_id);
  if (current_ != job_id || !cancel_flag_) return false;
  cancel_flag_->store(true);
  if (waiting_link_) waiting_link_->close();  // still waiting for the carriage: stop now
  return true;
}

void KnitDevice::resume(int64_t job_id, int from_row) {
  auto job = jobs_.store().get(job_id);
  if (!job) throw BadInput("no " + job_tag(job_id));
  if (job->state != JobState::interrupted)
    throw BadInput(job_tag(job_id) + " is " + state_name(job->state) +
                             "; only interrupted jobs can be resumed");
  if (from_row == 0)
    throw BadInput("say which row to continue from: atelierctl resume " +
                             std::to_string(job_id) + " --from-row N");
  std::optional<int> placement;
  {
    std::lock_guard lock(mu_);
    if (auto it = placements_.find(job_id); it != placements_.end()) placement = it->second;
  }
  int rows = 0;
  try {
    if (!placement) placement = choose_start(*job, {}, /*check_row=*/false).start_needle;
    rows = plan_job(*job, placement).rows();
  } catch (const std::exception& e) {
    throw BadInput(job_tag(job_id) + ": " + e.what());
  }
  if (from_row < 1 || from_row > rows)
    throw BadInput("row " + std::to_string(from_row) + " is outside the " +
                             (is_lace(job->kind) ? "chart" : "pattern") + " (rows 1 to " + std::to_string(rows) + ")");
  {
    std::lock_guard lock(mu_);
    resumes_[job_id] = from_row;
  }
  wake();
}

ayab::PlanParams KnitDevice::plan_params(std::optional<int> start_needle) const {
  ayab::PlanParams p;
  p.machine = *ayab::machine_from_name(config_.machine);
  p.mode = *ayab::knit_mode_from_name(config_.mode);
  if (config_.start_needle > 0) p.start_needle = config_.start_needle - 1;
  if (start_needle) p.start_needle = *start_needle;  // the job's own placement
  p.mirror = config_.mirror;
  return p;
}

std::optional<KnitDevice::Work> KnitDevice::next_work() {
  {
    std::lock_guard claim(claim_mutex());
    std::optional<Work> work;
    {
      std::lock_guard lock(mu_);
      while (!work && !resumes_.empty()) {
        auto [id, row] = *resumes_.begin();
        resumes_.erase(resumes_.begin());
        auto job = jobs_.store().get(id);
        if (job && job->state == JobState::interrupted) {
          work = Work{id, row, std::nullopt, ""};
          if (auto it = placements_.find(id); it != placements_.end()) work->start_needle = it->second;
        }
      }
    }
    if (work) {
      jobs_.transition(work->id, JobState::running,
                       "knitting on " + config_.name + " from row " + std::to_string(work->from_row),
                       config_.name);
      return work;
    }
  }
  Work work{0, 1, std::nullopt, ""};
  auto id = claim_ready([&](const Job& job) {
    std::optional<ChosenStart> chosen;
    {
      std::lock_guard lock(mu_);
      if (auto it = starts_.find(job.id); it != starts_.end()) {
        chosen = std::move(it->second);
        starts_.erase(it);
      }
    }
    if (!chosen) {  // started on its own (autostart): its sidecar keys are checked now
      try {
        chosen = choose_start(job, {});
      } catch (const CannotPlan&) {
        chosen = ChosenStart{};  // knit() fails it with the plan's own reason
      } catch (const std::exception& e) {
        // "kh930: start_needle ..." said by the device, as its other failures are.
        work.refused = config_.name + ": " + e.what();
        return "knitting on " + config_.name;
      }
    }
    work.from_row = chosen->from_row;
    work.start_needle = chosen->start_needle;
    return "knitting on " + config_.name + (chosen->text.empty() ? "" : " " + chosen->text);
  });
  if (!id) return std::nullopt;
  work.id = *id;
  return work;
}

bool KnitDevice::run_next() {
  auto work = next_work();
  if (!work) return false;
  knit(*work);
  return true;
}

void KnitDevice::end_early(int64_t id, int rows_done, bool knitting_started, const std::string& in_progress) {
  if (stopping()) {
    // Never canceled by a shutdown, and never resumed without an operator.
    jobs_.transition(id, JobState::interrupted, "atelierd stopped after row " +
                                                    std::to_string(rows_done) + "; " +
                                                    resume_hint(id, rows_done, in_progress));
  } else if (knitting_started) {
    jobs_.transition(id, JobState::canceled,
                     "canceled after row " + std::to_string(rows_done) +
                         "; the machine was sent the blank last line and is ready");
  } else {
    jobs_.transition(id, JobState::canceled, "canceled by user before knitting started");
  }
}

void KnitDevice::knit(const Work& work) {
  const int64_t id = work.id;
  auto job = jobs_.store().get(id);
  if (!job) return;
  OnMachine<std::atomic<bool>> on_machine(*this, id, cancel_flag_);
  std::atomic<bool>& cancel = on_machine.handle();
  if (stopping()) cancel = true;  // stop() came between the claim and now

  set_state("busy", job_tag(id));
  if (!work.refused.empty()) {
    jobs_.transition(id, JobState::failed, work.refused);  // nothing was sent
    return;
  }
  {
    std::lock_guard lock(mu_);
    placements_[id] = work.start_needle;
  }

  // Rows knitted so far, counted from 1 as the knitter counts them.
  int rows_done = work.from_row - 1;
  bool knitting_started = false;
  // A lace chart row stopped between its first and last pass: its stitches may have been
  // moved by the lace carriage and not knitted yet, so resuming that row as planned would
  // move them again. Said with the resume hint.
  std::string in_progress;
  try {
    const JobPlan job_plan = plan_job(*job, work.start_needle);
    const ayab::KnitPlan& plan = job_plan.plan;
    const int total_rows = job_plan.rows();
    jobs_.store().set_progress(id, rows_done, total_rows);

    auto port = resolve_();
    if (!port) throw LinkLost("the machine is not connected");
    std::unique_ptr<Transport> link = open_(*port);
    struct WaitingLink {  // cleared however this scope is left
      KnitDevice* d;
      ~WaitingLink() {
        std::lock_guard lock(d->mu_);
        d->waiting_link_ = nullptr;
      }
    } waiting{this};
    {
      std::lock_guard lock(mu_);
      if (cancel.load()) throw LinkLost("canceled before the machine was ready");
      waiting_link_ = link.get();
    }
    const auto& starts = job_plan.row_start;
    const int from_pass = starts[static_cast<size_t>(work.from_row - 1)];
    const bool whole_rows = is_lace(job->kind);
    const std::string row_word = whole_rows ? "chart row " : "row ";
    // What the knitter should do now: the device's detail and the running job's reason.
    auto say = [&](const std::string& what) {
      set_detail(job_tag(id) + ": " + what);
      jobs_.progress_reason(id, rows_done, total_rows, what);
    };
    ayab::HostSession session(*link, timeouts_, clock_);
    session.set_events({[&] { say(turn_mark_prompt(plan, from_pass)); },
                        [&] {
                          say("all " + std::to_string(total_rows) +
                              " rows knitted; one more pass to finish: move the carriage across once more "
                              "(the machine beeps twice)");
                        }});
    session.connect();
    try {
      session.init(plan.machine);
    } catch (const ayab::MachineSilent& e) {
      // Hung while the knitter was to move the carriage (e.g. a garbled byte): reset it once.
      log::info(std::string(e.what()) + "; resetting the board (DTR) and trying once more", job_fields(*job));
      link->pulse_dtr(kDtrResetPulse);
      try {
        session.connect();
        session.init(plan.machine);
      } catch (const ayab::AyabError& again) {
        throw ayab::AyabError(std::string(again.what()) +
                              "; atelier reset it, but it still does not answer: unplug it and plug it back");
      }
    }
    try {
      session.start(plan);
    } catch (const ayab::StartRefused& e) {
      if (!e.wrong_state()) throw;
      // A board that was not reset (e.g. still knitting for a daemon that crashed): reset it
      // through DTR and go through the handshake once more. Refused again: the job fails.
      log::info(std::string(e.what()) + "; resetting the board (DTR) and trying once more", job_fields(*job));
      link->pulse_dtr(kDtrResetPulse);
      session.connect();
      session.init(plan.machine);
      session.start(plan);
    }
    {
      std::lock_guard lock(mu_);
      waiting_link_ = nullptr;
    }
    knitting_started = true;
    // Where the carriage is in the lace plan: "; next: lace carriage" after `passes_done`.
    auto next_carriage = [&plan](int passes_done) -> std::string {
      if (plan.carriage.empty() || passes_done >= static_cast<int>(plan.carriage.size())) return "";
      return plan.carriage[static_cast<size_t>(passes_done)] == ayab::Carriage::lace ? "; next: lace carriage"
                                                                                    : "; next: knit carriage";
    };
    say("knitting " + row_word + std::to_string(rows_done + 1) + " of " + std::to_string(total_rows) +
        next_carriage(from_pass));
    // A lace row is transfers, then knitting: stopped between them, its stitches would sit
    // moved but unknitted, and resuming from that row would move them again. So a canceled
    // lace job stops where a chart row begins (the knitter finishes the row in hand). The
    // daemon stopping does not wait for that.
    std::atomic<bool> stop_at_row_start{cancel.load()};
    try {
      session.knit(plan, from_pass, [&](const ayab::KnitProgress& p) {
        if (cancel.load() && (stopping() || std::binary_search(starts.begin(), starts.end(), p.passes_done)))
          stop_at_row_start = true;
        in_progress.clear();
        if (whole_rows && !std::binary_search(starts.begin(), starts.end(), p.passes_done)) {
          const auto next = std::upper_bound(starts.begin(), starts.end(), p.passes_done);
          const int row = static_cast<int>(next - starts.begin());  // 1-based chart row in hand
          in_progress = "chart row " + std::to_string(row) + " stopped after " +
                        std::to_string(p.passes_done - *(next - 1)) + " of its " +
                        std::to_string(*next - *(next - 1)) +
                        " passes: its stitches may be moved but not knitted; put them back as " +
                        (row == 1 ? std::string("the cast-on") : "chart row " + std::to_string(row - 1)) +
                        " left them (or finish the row by hand and resume from row " + std::to_string(row + 1) +
                        "); ";
        }
        // Rows whose every pass is done.
        rows_done = static_cast<int>(std::upper_bound(starts.begin() + 1, starts.end(), p.passes_done) -
                                     (starts.begin() + 1));
        if (rows_done < total_rows)
          say("knitting " + row_word + std::to_string(rows_done + 1) + " of " + std::to_string(total_rows) +
              next_carriage(p.passes_done));
        else
          say("knitted " + row_word + std::to_string(rows_done) + " of " + std::to_string(total_rows));
      }, whole_rows ? stop_at_row_start : cancel);
    } catch (const ayab::LineGarbled& e) {
      // The pass knitted something else than planned: its row is not knitted as planned, and
      // the firmware will not ask for another line. The knitter must undo that row.
      const int row = static_cast<int>(std::upper_bound(starts.begin(), starts.end(), e.pass) - starts.begin());
      rows_done = row - 1;
      log::info(e.what(), job_fields(*job));
      link->close();
      jobs_.transition(id, JobState::interrupted,
                       row_word + std::to_string(row) +
                           (e.early ? " was knitted before its line reached the machine (the carriage was pushed "
                                      "too soon: wait for the beep)"
                                    : " was knitted from a line garbled on the cable (the machine did not ask for "
                                      "the next line after it)") +
                           ": stop the carriage, unravel that row" +
                           (whole_rows ? " and put its stitches back as the row before left them" : "") +
                           ", then continue with: atelierctl resume " + std::to_string(id) + " --from-row " +
                           std::to_string(row));
      return;
    } catch (const ayab::MachineSilent& e) {
      // Firmware 1.0 hangs on a garbled SLIP escape until reset: reset it through DTR, so the
      // knitter can resume without unplugging it.
      log::info(std::string(e.what()) + "; resetting the board (DTR)", job_fields(*job));
      link->pulse_dtr(kDtrResetPulse);
      std::string after_reset = "atelier reset it";
      try {
        session.connect();
      } catch (const std::exception&) {
        after_reset = "atelier reset it, but it still does not answer: unplug it and plug it back";
      }
      link->close();
      if (rows_done >= total_rows) {
        jobs_.transition(id, JobState::completed,
                         "knitted " + std::to_string(total_rows) + " rows on " + config_.name +
                             "; the machine stopped answering before its last (empty) pass, and " + after_reset);
      } else {
        jobs_.transition(id, JobState::interrupted,
                         "the knitting machine stopped answering after " + row_word + std::to_string(rows_done) +
                             " (its firmware hung, e.g. on a byte garbled on the cable); " + after_reset + "; " +
                             resume_hint(id, rows_done, in_progress));
      }
      return;
    }
    link->close();
    // Stopped while waiting for the last (empty) pass: every row is knitted all the same.
    if (cancel.load() && rows_done < total_rows) {
      end_early(id, rows_done, true, in_progress);
    } else {
      jobs_.transition(id, JobState::completed,
                       "knitted " + std::to_string(total_rows) + " rows on " + config_.name);
    }
  } catch (const LinkLost& e) {
    if (cancel.load() && !knitting_started) {
      end_early(id, rows_done, false);  // the link was closed on purpose, during the wait
    } else {
      set_state("offline", e.what());
      jobs_.transition(id, JobState::interrupted, "device disconnected after row " +
                                                      std::to_string(rows_done) + "; " +
                                                      resume_hint(id, rows_done, in_progress));
    }
  } catch (const ayab::AyabError& e) {
    if (knitting_started) {
      jobs_.transition(id, JobState::interrupted,
                       std::string(e.what()) + " (after row " + std::to_string(rows_done) + "; " +
                           resume_hint(id, rows_done, in_progress) + ")");
    } else {
      jobs_.transition(id, JobState::failed, config_.name + ": " + e.what());
    }
  } catch (const CannotKnit& e) {
    jobs_.transition(id, JobState::failed, e.what());  // nothing was sent
  } catch (const std::exception& e) {
    // The pattern does not fit the machine, or its file is unreadable: nothing was knitted.
    jobs_.transition(id, JobState::failed, config_.name + ": " + e.what());
  }  // the job's end is logged by JobLog (job_log.h)
}

}  // namespace atelier
