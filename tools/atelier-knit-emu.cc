// atelier-knit-emu: AYAB firmware 1.0.0 (API v6) on a Brother KH-9xx / KH-270, on a
// pseudo-terminal, with a simulated knitter pushing the carriage.
//
//   atelier-knit-emu --machine kh930|kh910|kh270 --link PATH [--record FILE] [--row-ms N]
//                    [--boot-ms N] [--fw-suffix TEXT] [--fault SPEC ...] [--verbose]
//
// The firmware model (tools/knit_emu/firmware.h) runs on a real-time clock (ms since start);
// this file only wires it to a pty and implements the link faults. On start it prints
// "atelier-knit-emu: kh930 on /dev/pts/N linked at PATH" on stdout, and a line starting
// "atelier-knit-emu: DTR dropped" each time the host goes away; SIGTERM/SIGINT remove the
// link and exit 0. --fault specs are listed in tools/knit_emu/faults.h.
//
// The record (--record FILE): one line of 0/1 per pass over the working range, the needles the
// carriage actually selected (firmware.h says which passes), appended as they are knitted.
// drop-after-row=N: the reply that confirms row N (the next reqLine) is still written (and up to
// 1 s is given for the host to read it), then
// the pty is closed and the link removed; after replug-ms a new pty appears at the same path
// with a freshly booted firmware (boot delay included), like a replugged Arduino. The record
// file keeps appending and rows keep their numbering.
// Reset: an Uno resets when a host OPENS the port: DTR rises (the tty asserts it on open), and
// the falling edge of DTR# through the auto-reset capacitor pulls RESET low. Closing drops DTR
// (HUPCL), which the capacitor passes as a rising edge: no reset. So each open is a fresh
// firmware that loses what arrives in its first --boot-ms (default 1000, the bootloader), back
// in wait-for-machine with the carriage where it was; unless --fault no-dtr-reset, when the next
// host finds the firmware as the last one left it. tools/emu/pty_link.h detects open and close.
#include <algorithm>
#include <poll.h>
#include <signal.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>

#include "base/cli_parse.h"
#include "drivers/ayab/messages.h"
#include "tools/knit_emu/faults.h"
#include "tools/knit_emu/firmware.h"
#include "tools/emu/pty_link.h"

namespace {

// The program's least default knitter patience (ms): see main().
constexpr int64_t kKnitterPatienceFloorMs = 3000;

using atelier::knit_emu::Faults;
using atelier::knit_emu::Firmware;
using atelier::knit_emu::FirmwareOptions;
using atelier::knit_emu::KnittedRow;
using atelier::emu::PtyLink;
namespace ab = atelier::ayab;

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

int64_t clock_ms() {
  static const auto t0 = std::chrono::steady_clock::now();
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - t0).count();
}

// Logs the messages in a byte stream for --verbose (a decoder per direction).
void log_traffic(ab::SlipDecoder& dec, const ab::Bytes& bytes, ab::MachineType m, const char* arrow) {
  for (const auto& p : dec.feed(bytes)) {
    const auto d = ab::decode(p, ab::line_bytes(m));
    if (d.message) std::cerr << "atelier-knit-emu: " << arrow << ' ' << ab::describe(*d.message) << '\n';
    else std::cerr << "atelier-knit-emu: " << arrow << " malformed packet: " << ab::error_text(d.error) << '\n';
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"AYAB v6 knitting-machine emulator on a pseudo-terminal"};
  std::string machine_arg, link_path, record_path, suffix;
  int64_t row_ms = 2000, boot_ms = 1000;
  std::vector<std::string> fault_specs;
  bool verbose = false;
  app.add_option("--machine", machine_arg, "kh930, kh910 or kh270")->required();
  app.add_option("--link", link_path, "symlink to create for the pty slave")->required();
  app.add_option("--record", record_path, "append each knitted row (0/1 per needle) to FILE");
  app.add_option("--row-ms", row_ms, "carriage pass time in ms (0: instant, for benchmarks)")->check(CLI::NonNegativeNumber);
  app.add_option("--boot-ms", boot_ms, "input lost this long after the port is opened (the board resets; default 1000)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--fw-suffix", suffix, "firmware version suffix in cnfInfo (release firmware: none)");
  app.add_option("--fault", fault_specs, "fault to inject (repeatable); see the list below");
  app.add_flag("--verbose", verbose, "log protocol traffic to stderr");
  app.set_version_flag("--version", "atelier-knit-emu " ATELIER_VERSION, "print \"atelier-knit-emu VERSION\" and exit");
  app.footer(
      "Faults (--fault SPEC, repeatable):\n"
      "  drop-after-row=N[:M]  unplug after row N (rows counted from 1 over the emulator's life),\n"
      "                        replug a fresh firmware at the same link after M ms (default 1000)\n"
      "  replug-ms=M           replug delay on its own\n"
      "  corrupt=F             corrupt a fraction F in [0,1] of the received bytes\n"
      "  seed=S                seed of the corruption (default 1)\n"
      "  corrupt-line=N        the Nth cnfLine received arrives with a needle byte broken (bad CRC:\n"
      "                        the garbled line stays in the buffer, as on firmware 1.0)\n"
      "  bad-escape-after-row=N  after row N the next byte received is SLIP ESC + an invalid byte:\n"
      "                        the firmware hangs until it is reset\n"
      "  silent-after-row=N    answer nothing after row N\n"
      "  api=V                 report API version V in cnfInfo (e.g. 5)\n"
      "  delay-ms=N            delay every reply by N ms\n"
      "  no-dtr-reset          do not reset when a host opens the port (auto-reset disabled)\n"
      "  knitter-pause-ms=M    the knitter pushes the next pass M ms after the beep (default 10)\n"
      "  knitter-patience-ms=M with no beep, the knitter pushes after M ms (default 2 x row-ms,\n"
      "                        at least 3000: a knitter waits a few seconds for the beep)\n"
      "  impatient-knitter     the knitter pushes pause ms after each pass, beep or not\n"
      "Otherwise the board resets each time a host opens the port (DTR) and loses --boot-ms of input.");
  if (auto stop = atelier::parse_command_line(app, argc, argv)) return *stop;

  const auto machine = ab::machine_from_name(machine_arg);
  if (!machine) {
    std::cerr << "atelier-knit-emu: --machine " << machine_arg << ": unknown machine (kh930, kh910, kh270)\n";
    return 2;
  }
  Faults faults;
  for (const auto& spec : fault_specs) {
    if (auto error = atelier::knit_emu::apply_fault(spec, faults); !error.empty()) {
      std::cerr << "atelier-knit-emu: " << error << '\n';
      return 2;
    }
  }
  // A knitter at a real machine waits a few seconds for the beep before pushing anyway; the
  // model's own default (2 pass times) is for in-process tests on a simulated clock, where a
  // host never lags. On a loaded box a host can take longer than two 10 ms passes to answer.
  if (!faults.knitter_patience_ms) faults.knitter_patience_ms = std::max<int64_t>(2 * row_ms, kKnitterPatienceFloorMs);

  std::ofstream record;
  if (!record_path.empty()) {
    record.open(record_path, std::ios::app);
    if (!record) {
      std::cerr << "atelier-knit-emu: " << record_path << ": cannot open the record file for appending\n";
      return 1;
    }
  }

  struct sigaction sa {};
  sa.sa_handler = on_signal;  // no SA_RESTART: poll() returns EINTR
  sigaction(SIGTERM, &sa, nullptr);
  sigaction(SIGINT, &sa, nullptr);
  signal(SIGPIPE, SIG_IGN);

  int rows_total = 0;
  bool drop_pending = false;
  auto on_row = [&](const KnittedRow& row) {
    rows_total = row.number;
    if (record.is_open()) {
      record << row.needles << '\n';
      record.flush();
    }
    if (faults.drop_after_row && row.number == *faults.drop_after_row) drop_pending = true;
  };
  std::unique_ptr<PtyLink> link;
  std::unique_ptr<Firmware> fw;
  // Power-on or reset: a fresh firmware; the carriage stays where it was, counts go on.
  auto boot_firmware = [&] {
    FirmwareOptions opt;
    opt.machine = *machine;
    opt.row_ms = row_ms;
    opt.boot_ms = boot_ms;
    opt.rows_before = rows_total;
    opt.suffix = suffix;
    opt.faults = faults;
    if (fw) {
      opt.cnf_lines_before = fw->cnf_lines_received();
      opt.carriage_position = fw->carriage_position();
    }
    return std::make_unique<Firmware>(opt, on_row, clock_ms());
  };
  try {
    link = std::make_unique<PtyLink>(link_path);
  } catch (const std::exception& e) {
    std::cerr << "atelier-knit-emu: " << e.what() << '\n';
    return 1;
  }
  fw = boot_firmware();
  std::cout << "atelier-knit-emu: " << ab::machine_name(*machine) << " on " << link->slave_name()
            << " linked at " << link_path << std::endl;

  ab::Bytes pending;  // output not yet accepted by the pty
  int64_t replug_at = 0;
  ab::SlipDecoder log_in, log_out;
  // While no host has the port open the master polls hung up at once, forever: look for a
  // host this often instead.
  constexpr int64_t kLookForHostMs = 2;
  bool connected = false;  // a host has the slave open (DTR up)
  // The host closed the port or died: DTR dropped. No reset yet: that comes when the next
  // host opens the port (see the top of this file). What the firmware sends meanwhile is lost.
  auto hang_up = [&] {
    connected = false;
    pending.clear();  // nobody to send it to
    if (faults.dtr_reset)
      std::cout << "atelier-knit-emu: DTR dropped (the host closed the port): the board resets when a host opens it"
                << std::endl;
    else
      std::cout << "atelier-knit-emu: DTR dropped (the host closed the port): no reset (fault no-dtr-reset)"
                << std::endl;
    try {
      link->after_hangup();
    } catch (const std::exception& e) {
      std::cerr << "atelier-knit-emu: " << e.what() << '\n';
    }
  };
  while (!g_stop) {
    const int64_t now = clock_ms();
    if (!link) {
      if (now >= replug_at) {
        try {
          link = std::make_unique<PtyLink>(link_path);
        } catch (const std::exception& e) {
          std::cerr << "atelier-knit-emu: replug failed: " << e.what() << '\n';
          return 1;
        }
        fw = boot_firmware();
        pending.clear();
        connected = false;
        log_in = ab::SlipDecoder{};
        log_out = ab::SlipDecoder{};
        std::cerr << "atelier-knit-emu: replugged on " << link->slave_name() << '\n';
        continue;
      }
      ::poll(nullptr, 0, static_cast<int>(std::min<int64_t>(replug_at - now, 200)));
      continue;
    }
    if (!connected && link->host_connected()) {
      connected = true;
      if (faults.dtr_reset) {  // DTR rises: the board resets and boots
        fw->advance_to(clock_ms());
        fw = boot_firmware();
        log_in = ab::SlipDecoder{};
        log_out = ab::SlipDecoder{};
        if (verbose) std::cerr << "atelier-knit-emu: a host opened the port: the board resets\n";
      }
    }

    int64_t timeout = 200;  // bounded so a signal between checks is seen soon
    if (auto next = fw->next_event_ms()) timeout = std::clamp<int64_t>(*next - now, 0, timeout);
    if (!connected) timeout = std::min(timeout, kLookForHostMs);
    pollfd pfd{link->master_fd(), static_cast<short>(POLLIN | (pending.empty() ? 0 : POLLOUT)), 0};
    const int ready = ::poll(&pfd, connected ? 1 : 0, static_cast<int>(timeout));
    if (ready < 0 && errno != EINTR) {
      std::perror("atelier-knit-emu: poll");
      return 1;
    }
    fw->advance_to(clock_ms());
    if (connected && ready > 0 && (pfd.revents & POLLIN)) {
      uint8_t buf[4096];
      const ssize_t n = ::read(link->master_fd(), buf, sizeof buf);
      if (n > 0) {
        ab::Bytes in(buf, buf + n);
        if (verbose) log_traffic(log_in, in, *machine, "host ->");
        fw->receive(in);
      } else if (n < 0 && errno == EIO) {
        hang_up();
      }
    } else if (connected && ready > 0 && (pfd.revents & (POLLHUP | POLLERR))) {
      hang_up();  // what the host wrote before it went has been read (POLLIN comes first)
    }
    fw->advance_to(clock_ms());
    const ab::Bytes out = fw->take_output();
    if (!connected) continue;  // a serial line with no host loses what is sent
    if (verbose && !out.empty()) log_traffic(log_out, out, *machine, "emu  ->");
    pending.insert(pending.end(), out.begin(), out.end());
    // The drop waits for the reqLine that confirms row N to the host (it comes once the
    // carriage is past the working range), so the host knows exactly what was knitted.
    bool confirms_row = false;
    for (size_t i = 0; i + 1 < out.size(); ++i)
      if (out[i] == 0xC0 && out[i + 1] == static_cast<uint8_t>(ab::MsgId::reqLine)) confirms_row = true;
    while (!pending.empty()) {
      const ssize_t n = ::write(link->master_fd(), pending.data(), pending.size());
      if (n <= 0) break;  // EAGAIN: the host is not reading; retry on POLLOUT
      pending.erase(pending.begin(), pending.begin() + n);
    }
    if (drop_pending && confirms_row) {
      drop_pending = false;
      // Let the host read the reqLine confirming the last row (bounded: it may not be reading).
      if (pending.empty()) link->drain(1000);
      std::cerr << "atelier-knit-emu: link dropped after row " << rows_total << " (fault)\n";
      link->close();
      link.reset();  // the firmware stays for its carriage and counts: the replug boots a new one
      replug_at = clock_ms() + faults.replug_ms;
    }
  }
  link.reset();  // removes the symlink
  return 0;
}
