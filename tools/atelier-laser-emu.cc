// atelier-laser-emu: a GRBL 1.1h laser controller (laser mode, $30=1000) on a pseudo-terminal.
//
//   atelier-laser-emu --link PATH [--record FILE] [--render PNG] [--px-per-mm N] [--time-scale F]
//                     [--work-area WxH] [--fault SPEC ...] [--replug-ms MS] [--baud B]
//                     [--setting N=V ...] [--homing-origin stock|force]
//
// The controller model (tools/laser_emu/controller.h) runs on the steady clock; this file wires
// it to a pty, paces nothing itself (the model times every byte at the baud rate), injects the
// link faults (tools/laser_emu/faults.h) and writes the record. On start it prints
// "atelier-laser-emu: GRBL 1.1h on /dev/pts/N linked at PATH" on stdout, and a line starting
// "atelier-laser-emu: DTR dropped" each time the host goes away. SIGTERM/SIGINT write
// the record and render, remove the link and exit 0.
// The port's DTR line: when the last host descriptor on the pty closes (the host closed the port,
// or was killed) the board restarts at once as an Uno's auto-reset does (Controller::hangup():
// beam off, motion, planner and buffers gone, Alarm if homing is enabled), recorded as a
// "hangup" event; the banner goes out when a host next opens the port (tools/emu/pty_link.h).
// --record FILE: JSON (tools/laser_emu/record.h), written atomically (temp file + rename) at
// exit and about every 0.5 s while it changes (on a thread of its own, so writing never
// delays the controller). --render PNG: what was burned, written with the
// record: white work area at --px-per-mm, machine (X, Y) at pixel (X*ppm, (H-Y)*ppm).
#include <poll.h>
#include <signal.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <condition_variable>
#include <opencv2/imgcodecs.hpp>

#include "base/cli_parse.h"
#include "tools/emu/pty_link.h"
#include "tools/laser_emu/controller.h"
#include "tools/laser_emu/faults.h"
#include "tools/laser_emu/record.h"

namespace {

namespace le = atelier::laser_emu;
using atelier::emu::PtyLink;

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

const auto g_t0 = std::chrono::steady_clock::now();
int64_t clock_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - g_t0).count();
}

// Writes `data` to `path` atomically: a reader sees the old file or the new one, never half.
bool write_atomically(const std::string& path, const std::string& data) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f || !f.write(data.data(), static_cast<std::streamsize>(data.size()))) return false;
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  return !ec;
}

void save(const le::Record& record, const std::string& record_path, const std::string& render_path, double ppm) {
  if (!record_path.empty() && !write_atomically(record_path, le::to_json(record).dump(1) + "\n"))
    std::cerr << "atelier-laser-emu: " << record_path << ": cannot write the record\n";
  if (!render_path.empty()) {
    std::vector<uchar> png;
    if (!cv::imencode(".png", le::render_burn(record, ppm), png) ||
        !write_atomically(render_path, std::string(png.begin(), png.end())))
      std::cerr << "atelier-laser-emu: " << render_path << ": cannot write the render\n";
  }
}

// Writes snapshots of the record on its own thread, so a slow write (the render is a PNG of
// the whole bed) never holds up the controller - above all not its answer to a hang-up. The
// newest snapshot wins; finish() writes the last one and joins.
class RecordWriter {
 public:
  RecordWriter(std::string record_path, std::string render_path, double ppm)
      : record_path_(std::move(record_path)), render_path_(std::move(render_path)), ppm_(ppm),
        thread_([this] { run(); }) {}
  ~RecordWriter() { finish(std::nullopt); }

  void submit(le::Record r) {
    {
      std::lock_guard lock(mu_);
      next_ = std::move(r);
    }
    wake_.notify_one();
  }
  // Stops the thread, then writes `last` (if any) on this one.
  void finish(std::optional<le::Record> last) {
    if (thread_.joinable()) {
      {
        std::lock_guard lock(mu_);
        stop_ = true;
      }
      wake_.notify_one();
      thread_.join();
    }
    if (last) save(*last, record_path_, render_path_, ppm_);
  }

 private:
  void run() {
    std::unique_lock lock(mu_);
    for (;;) {
      wake_.wait(lock, [&] { return stop_ || next_; });
      if (stop_) return;
      le::Record r = std::move(*next_);
      next_.reset();
      lock.unlock();
      save(r, record_path_, render_path_, ppm_);
      lock.lock();
    }
  }

  const std::string record_path_, render_path_;
  const double ppm_;
  std::mutex mu_;
  std::condition_variable wake_;
  std::optional<le::Record> next_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"GRBL 1.1h laser controller emulator on a pseudo-terminal"};
  std::string link_path, record_path, render_path, work_area = "400x400";
  double ppm = 5, time_scale = 1;
  std::vector<std::string> fault_specs;
  int64_t replug_ms = -1;
  int baud = 115200;
  std::vector<std::string> setting_specs;
  std::string homing_origin = "stock";
  app.add_option("--link", link_path, "symlink to create for the pty slave")->required();
  app.add_option("--record", record_path, "write the toolpath and events as JSON to FILE");
  app.add_option("--render", render_path, "write a PNG of what was burned");
  app.add_option("--px-per-mm", ppm, "render resolution (default 5)")->check(CLI::PositiveNumber);
  app.add_option("--time-scale", time_scale, "multiply motion and dwell times (0.01 = 100x faster)")
      ->check(CLI::PositiveNumber);
  app.add_option("--work-area", work_area, "WxH in mm: soft limits $130/$131 (default 400x400)");
  app.add_option("--fault", fault_specs, "fault to inject (repeatable); see below");
  app.add_option("--replug-ms", replug_ms, "after a drop fault, replug after MS ms")->check(CLI::NonNegativeNumber);
  app.set_version_flag("--version", "atelier-laser-emu " ATELIER_VERSION, "print \"atelier-laser-emu VERSION\" and exit");
  app.add_option("--baud", baud, "serial rate that paces every byte (default 115200)")->check(CLI::PositiveNumber);
  app.add_option("--setting", setting_specs,
                 "N=V: a setting stored over the defaults, in order (repeatable; e.g. --setting 22=1 --setting 20=1)");
  app.add_option("--homing-origin", homing_origin,
                 "stock (default: homed machine space -$130..0 per axis) or force (built with "
                 "HOMING_FORCE_SET_ORIGIN: axes homing towards negative, $23 bit set, in 0..$13x)")
      ->check(CLI::IsMember({"stock", "force"}));
  app.footer(
      "Behaves like GRBL 1.1h (defaults.h DEFAULTS_GENERIC) as a laser owner stores it: laser mode\n"
      "$32=1, the work area as $130/$131, 80 steps/mm, 6000 mm/min, 500 mm/s^2; homing and soft\n"
      "limits off until --setting 22=1 --setting 20=1. See tools/laser_emu/controller.h.\n"
      "Render: white image of the work area at --px-per-mm; machine (X,Y) mm is pixel\n"
      "(X*ppm, (H-Y)*ppm), Y up; burned segments dark, darker for more power.\n"
      "Faults (--fault SPEC, repeatable; lines numbered from 1 over the emulator's life, every\n"
      "line counted, $ commands and empty lines too):\n"
      "  drop-at-line=N          after answering line N, close the pty and remove the link\n"
      "                          (board unpowered); --replug-ms MS brings a fresh one back\n"
      "  stall-at-line=N         after answering line N, stop reading and answering\n"
      "  alarm-at-line=N[:CODE]  raise ALARM:CODE (default 1, hard limit) when line N is taken\n"
      "Closing the port (or the host dying) drops DTR: the board restarts at once, beam off.");
  if (auto stop = atelier::parse_command_line(app, argc, argv)) return *stop;

  le::Faults faults;
  for (const auto& spec : fault_specs) {
    if (auto error = le::apply_fault(spec, faults); !error.empty()) {
      std::cerr << "atelier-laser-emu: " << error << '\n';
      return 2;
    }
  }
  const auto area = le::parse_work_area(work_area);
  if (!area) {
    std::cerr << "atelier-laser-emu: --work-area " << work_area << ": expected WxH in mm, e.g. 400x300\n";
    return 2;
  }

  std::vector<std::pair<int, double>> stored;
  for (const auto& spec : setting_specs) {
    const auto eq = spec.find('=');
    char* end = nullptr;
    const long id = eq == std::string::npos ? -1 : std::strtol(spec.c_str(), &end, 10);
    const char* value_text = eq == std::string::npos ? "" : spec.c_str() + eq + 1;
    char* value_end = nullptr;
    const double value = std::strtod(value_text, &value_end);
    if (id < 0 || end != spec.c_str() + eq || value_end == value_text || *value_end != '\0') {
      std::cerr << "atelier-laser-emu: --setting " << spec << ": expected N=V, e.g. 22=1\n";
      return 2;
    }
    stored.emplace_back(static_cast<int>(id), value);
  }

  struct sigaction sa {};
  sa.sa_handler = on_signal;  // no SA_RESTART: ppoll() returns EINTR
  sigaction(SIGTERM, &sa, nullptr);
  sigaction(SIGINT, &sa, nullptr);
  signal(SIGPIPE, SIG_IGN);

  const double epoch_at_zero =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count() -
      static_cast<double>(clock_us()) * 1e-6;
  le::Record record;
  record.work_w_mm = area->first;
  record.work_h_mm = area->second;
  bool drop_pending = false, dropped = false, stalled = false;
  auto power_on = [&](long lines_before) {
    le::ControllerOptions o;
    o.work_w_mm = area->first;
    o.work_h_mm = area->second;
    o.time_scale = time_scale;
    o.baud = baud;
    o.lines_before = lines_before;
    o.alarm_at_line = faults.alarm_at_line;
    o.alarm_code = faults.alarm_code;
    // The controller itself stops listening at the stall/drop line, so nothing after it runs.
    if (faults.stall_at_line) o.halt_after_line = faults.stall_at_line;
    if (faults.drop_at_line && !dropped && (!o.halt_after_line || *faults.drop_at_line < *o.halt_after_line))
      o.halt_after_line = faults.drop_at_line;
    o.epoch_at_zero_s = epoch_at_zero;
    o.banner_waits_for_host = true;  // printed when a host opens the port
    o.settings = stored;
    o.force_set_origin = homing_origin == "force";
    return std::make_unique<le::Controller>(o, record, clock_us());
  };

  std::unique_ptr<PtyLink> link;
  try {
    link = std::make_unique<PtyLink>(link_path);
  } catch (const std::exception& e) {
    std::cerr << "atelier-laser-emu: " << e.what() << '\n';
    return 1;
  }
  std::unique_ptr<le::Controller> ctl;
  try {
    ctl = power_on(0);
  } catch (const std::invalid_argument& e) {
    std::cerr << "atelier-laser-emu: --setting: " << e.what() << '\n';
    return 2;
  }
  std::cout << "atelier-laser-emu: GRBL 1.1h on " << link->slave_name() << " linked at " << link_path << std::endl;

  RecordWriter writer(record_path, render_path, ppm);
  std::string pending;  // output the pty has not accepted yet
  long lines_so_far = 0;
  int64_t replug_at = -1;
  uint64_t saved_version = ~0ull;
  int64_t last_save = 0;
  constexpr int64_t kSaveEveryUs = 500'000;
  // While no host has the port open the master polls hung up at once, forever: look for a
  // host this often instead (an Uno takes far longer to print its banner after the open).
  constexpr int64_t kLookForHostUs = 2'000;
  bool connected = false;  // a host has the slave open (DTR up)

  // The host closed the port or died: DTR dropped, the board restarts (beam off at once).
  auto hang_up = [&] {
    connected = false;
    pending.clear();  // nobody to send it to
    if (ctl) ctl->hangup(clock_us());
    std::cout << "atelier-laser-emu: DTR dropped (the host closed the port): board restarted, beam off" << std::endl;
    try {
      link->after_hangup();
    } catch (const std::exception& e) {
      std::cerr << "atelier-laser-emu: " << e.what() << '\n';
    }
  };

  while (!g_stop) {
    int64_t now = clock_us();
    if (link && !connected && link->host_connected()) {
      connected = true;
      if (ctl) ctl->host_connected(now);
    }
    if (ctl) {
      ctl->advance_to(now);
      const std::string out = ctl->take_output();
      if (connected) pending += out;  // a serial line with no host loses what is sent
      const long acked = ctl->last_acknowledged_line();
      if (faults.stall_at_line && !stalled && acked >= *faults.stall_at_line) {
        stalled = true;  // the controller has halted; its last answer still goes out
        std::cerr << "atelier-laser-emu: stalled after line " << acked << " (fault)\n";
      }
      if (faults.drop_at_line && !dropped && !drop_pending && acked >= *faults.drop_at_line) drop_pending = true;
    }
    while (link && connected && !pending.empty()) {
      const ssize_t n = ::write(link->master_fd(), pending.data(), pending.size());
      if (n <= 0) break;  // EAGAIN: the host is not reading; retry on POLLOUT
      pending.erase(0, static_cast<size_t>(n));
    }
    if (drop_pending && pending.empty() && ctl && !ctl->output_pending()) {
      drop_pending = false;
      dropped = true;
      link->drain(1000);  // let the host read the answer to line N (bounded)
      ctl->advance_to(clock_us());
      ctl->power_off();
      lines_so_far = ctl->lines_received();
      record.add_event(epoch_at_zero + static_cast<double>(clock_us()) * 1e-6, "drop");
      std::cerr << "atelier-laser-emu: link dropped after line " << ctl->last_acknowledged_line() << " (fault)\n";
      ctl.reset();
      link->close();
      link.reset();
      connected = false;
      pending.clear();
      if (replug_ms >= 0) replug_at = clock_us() + replug_ms * 1000;
    }
    if (!link && replug_at >= 0 && clock_us() >= replug_at) {
      try {
        link = std::make_unique<PtyLink>(link_path);
      } catch (const std::exception& e) {
        std::cerr << "atelier-laser-emu: replug failed: " << e.what() << '\n';
        break;
      }
      replug_at = -1;
      ctl = power_on(lines_so_far);
      record.add_event(epoch_at_zero + static_cast<double>(clock_us()) * 1e-6, "replug");
      std::cerr << "atelier-laser-emu: replugged on " << link->slave_name() << '\n';
    }

    now = clock_us();
    const bool moving = ctl && ctl->state() == le::MachineState::run;
    if ((record.version != saved_version || moving) && now - last_save >= kSaveEveryUs &&
        (!record_path.empty() || !render_path.empty())) {
      saved_version = record.version;
      last_save = now;
      writer.submit(ctl ? ctl->snapshot() : record);
    }

    // Sleep until the model's next event (sub-millisecond: ppoll), a byte from the host or its
    // hang-up, or 200 ms so signals and saves are seen; without a host, until it is time to
    // look for one again.
    int64_t timeout_us = 200'000;
    if (ctl)
      if (auto next = ctl->next_event_us()) timeout_us = std::clamp<int64_t>(*next - now, 0, timeout_us);
    if (replug_at >= 0) timeout_us = std::clamp<int64_t>(replug_at - now, 0, timeout_us);
    if (link && !connected) timeout_us = std::min(timeout_us, kLookForHostUs);
    const timespec ts{static_cast<time_t>(timeout_us / 1'000'000), static_cast<long>(timeout_us % 1'000'000) * 1000};
    pollfd pfd{-1, 0, 0};
    const bool watch = link && connected;
    if (watch) {
      pfd.fd = link->master_fd();
      pfd.events = static_cast<short>(((stalled || drop_pending) ? 0 : POLLIN) | (pending.empty() ? 0 : POLLOUT));
    }
    const int ready = ::ppoll(&pfd, watch ? 1 : 0, &ts, nullptr);
    if (ready < 0 && errno != EINTR) {
      std::perror("atelier-laser-emu: ppoll");
      return 1;
    }
    if (ready <= 0 || !watch) continue;
    if (pfd.revents & POLLIN) {
      char buf[4096];
      const ssize_t n = ::read(link->master_fd(), buf, sizeof buf);
      if (n > 0 && ctl) ctl->host_write(std::string_view(buf, static_cast<size_t>(n)), clock_us());
      if (n > 0) continue;  // what the host wrote before it went is read before the hang-up
      if (n < 0 && errno == EIO) hang_up();
    } else if (pfd.revents & (POLLHUP | POLLERR)) {
      hang_up();
    }
  }
  if (ctl) ctl->advance_to(clock_us());
  writer.finish(ctl ? ctl->snapshot() : record);
  link.reset();  // removes the symlink
  return 0;
}
