// atelierctl: command-line client of atelierd's control socket (docs/control-protocol.md).
// Exit codes: 0 ok, 1 the request failed (message on stderr), 2 usage, 3 daemon not reachable.
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "base/job_states.h"
#include "tools/ctl_client.h"
#include "tools/ctl_format.h"

namespace {

using atelier::ctl::ControlClient;
using nlohmann::json;

constexpr int kExitOk = 0;
constexpr int kExitFailed = 1;
constexpr int kExitUsage = 2;
constexpr int kExitUnreachable = 3;

// What the parsed command line asks for: one request and how to show its result.
struct Command {
  std::string verb;
  json args = json::object();
  bool json_output = false;
  std::function<std::string(const json&)> render = atelier::ctl::format_value;
  // Files the daemon is to read: opened here, with our rights, and passed with the request.
  std::vector<std::string> files = {};
};

const CLI::Validator kKeyValue(
    [](std::string& s) -> std::string {
      auto eq = s.find('=');
      if (eq == std::string::npos || eq == 0) return "expected key=value, got '" + s + "'";
      return "";
    },
    "KEY=VALUE");

// Job ids and row numbers: plain decimal integers (CLI11's number checks print float ranges).
CLI::Validator integer_at_least(std::int64_t minimum) {
  return CLI::Validator(
      [minimum](std::string& s) -> std::string {
        std::int64_t value = 0;
        bool digits = !s.empty() && s.size() <= 18 &&
                      s.find_first_not_of("0123456789") == std::string::npos;
        if (digits) value = std::stoll(s);
        if (!digits || value < minimum) {
          return "expected an integer >= " + std::to_string(minimum) + ", got '" + s + "'";
        }
        return "";
      },
      "INT");
}

std::string render_job_or_value(const json& result) {
  if (result.is_object() && result.contains("id") && result.contains("state")) {
    return atelier::ctl::format_job_line(result);
  }
  return atelier::ctl::format_value(result);
}

// A usage error found after parsing (an unknown --state): message, exit 2.
struct UsageError {
  std::string message;
};

// The first word that is neither an option nor an option's value: the verb, or "" if none.
std::string verb_word(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--socket") {
      ++i;  // its value
      continue;
    }
    if (!a.empty() && a[0] == '-') continue;
    return a;
  }
  return "";
}

std::string absolute_path(const std::string& file) {
  // The daemon resolves nothing against our working directory: send where the file really is.
  return std::filesystem::canonical(file).string();
}

void print_unreachable(const atelier::ctl::UnreachableError& e) {
  std::string hint = (e.error_number() == EACCES || e.error_number() == EPERM)
                         ? "is your user in the daemon's control group (atelier)?"
                         : "is atelierd running?";
  std::cerr << "atelierctl: " << e.what() << " (" << hint << ")\n";
}

int print_failure(const json& response) {
  std::string message = "the daemon rejected the request without a reason";
  if (response.contains("error") && response["error"].is_string()) {
    message = response["error"].get<std::string>();
  }
  std::cerr << "atelierctl: " << message << "\n";
  return kExitFailed;
}

bool response_ok(const json& response) {
  return response.contains("ok") && response["ok"].is_boolean() && response["ok"].get<bool>();
}

// A command's answer that says "settling" (the job moves on shortly: a start turning it
// running, a cancel ending it) is followed with `show` for a moment, so the confirmation shows
// the job as the command left it; the daemon answers at once and never waits itself.
json settled(ControlClient& client, const json& answer) {
  if (!answer.is_object() || !answer.value("settling", false) || !answer.contains("id")) return answer;
  const auto same_step = [&](const json& job) {
    return job.value("state", "") == answer.value("state", "") &&
           job.value("reason", "") == answer.value("reason", "");
  };
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(1500);
  while (std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const json shown = client.request("show", {{"id", answer["id"]}});
    if (!response_ok(shown) || !shown.contains("result")) break;  // gone: the answer is all we know
    if (!same_step(shown["result"])) return shown["result"];
  }
  return answer;
}

// Follows state changes until interrupted (exit 0). When the daemon goes away (a restart),
// says so on stderr and connects again, waiting 0.5 s, 1 s, 2 s, ... up to 5 s between
// attempts, and says when it is back. A daemon unreachable at the start ends it at once
// (UnreachableError: exit 3), as for every verb.
int run_watch(const std::string& socket) {
  // Ctrl-C is how a watch ends: leave quietly with success (every line is already flushed).
  struct sigaction quit {};
  quit.sa_handler = [](int) { _exit(kExitOk); };
  sigemptyset(&quit.sa_mask);
  sigaction(SIGINT, &quit, nullptr);
  sigaction(SIGTERM, &quit, nullptr);
  bool connected_once = false;
  bool reconnecting = false;
  auto backoff = std::chrono::milliseconds(500);
  for (;;) {
    std::string gone;  // why the stream ended, for the "daemon gone" line
    try {
      ControlClient client(socket);
      client.send(json{{"verb", "watch"}, {"args", json::object()}});
      auto first = client.receive(ControlClient::kDefaultTimeout);
      if (!first) {
        throw atelier::ctl::UnreachableError(
            "the daemon at " + socket + " closed the connection without answering", 0);
      }
      if (!response_ok(*first)) return print_failure(*first);
      if (reconnecting) std::cerr << "atelierctl: reconnected to " << socket << "\n";
      connected_once = true;
      reconnecting = false;
      backoff = std::chrono::milliseconds(500);
      for (;;) {
        auto message = client.receive(std::nullopt);
        if (!message) {
          gone = "the daemon at " + socket + " closed the connection";
          break;
        }
        if (message->contains("event")) {
          std::cout << atelier::ctl::format_event((*message)["event"]) << std::flush;
        } else if (message->contains("ok") && !response_ok(*message)) {
          gone = message->value("error", "");  // the daemon ended the watch, saying why
        }
      }
    } catch (const atelier::ctl::UnreachableError& e) {
      if (!connected_once) throw;
      gone = e.what();
    } catch (const atelier::ctl::ProtocolError& e) {
      if (!connected_once) throw;
      gone = e.what();
    }
    if (!reconnecting) {
      std::cerr << "atelierctl: daemon gone, reconnecting..." << (gone.empty() ? "" : " (" + gone + ")")
                << "\n";
      reconnecting = true;
    }
    std::this_thread::sleep_for(backoff);
    backoff = std::min<std::chrono::milliseconds>(backoff * 2, std::chrono::seconds(5));
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"atelierctl: control atelierd, the workshop fabrication daemon"};
  app.require_subcommand(1);
  app.fallthrough();  // --socket may also follow the verb
  std::string socket = atelier::ctl::default_socket_path();
  app.add_option("--socket", socket,
                 "control socket (default: $ATELIER_SOCKET, else /run/atelier/control.sock)")
      ->type_name("PATH");
  app.set_version_flag("--version", "atelierctl " ATELIER_VERSION, "print \"atelierctl VERSION\" and exit");

  Command cmd;
  std::int64_t id = 0;
  std::int64_t from_row = 0;
  std::string state, kind, file, wood_id;
  std::int64_t limit = 0;
  bool all = false;
  std::vector<std::string> sets;

  auto add_id = [&](CLI::App* sub) {
    sub->add_option("ID", id, "job id")->required()->check(integer_at_least(1));
  };
  auto add_json = [&](CLI::App* sub) {
    sub->add_flag("--json", cmd.json_output, "print the daemon's result as JSON");
  };
  auto add_sets = [&](CLI::App* sub) {
    sub->add_option("--set", sets, "parameter override (repeatable)")
        ->type_name("KEY=VALUE")
        ->allow_extra_args(false)
        ->check(kKeyValue);
  };

  auto* status = app.add_subcommand("status", "daemon, devices, queue counts");
  auto* list = app.add_subcommand("list", "jobs, newest first (the 1000 newest unless --limit or --all)");
  list->add_option("--state", state, "only jobs in this state (" + atelier::job_state_list_text() + ")");
  list->add_option("--kind", kind, "only jobs of this kind (one the daemon converts)");
  auto* limit_option = list->add_option("--limit", limit, "the N newest jobs (default 1000)")
                           ->type_name("N")
                           ->check(integer_at_least(1));
  list->add_flag("--all", all, "every job")->excludes(limit_option);
  add_json(list);
  auto* show = app.add_subcommand("show", "one job, its outputs and history");
  add_id(show);
  add_json(show);
  auto* submit = app.add_subcommand("submit", "queue a file as a job (same path as the hot folder)");
  submit->add_option("FILE", file, "input file")->required()->check(CLI::ExistingFile);
  submit->add_option("--kind", kind, "job kind (knit, lace, embroidery, ...)")->required();
  add_sets(submit);
  auto* start = app.add_subcommand(
      "start", "arm a ready job (knitting: the knitter has cast on; laser: the sheet is in)");
  add_id(start);
  std::int64_t start_row = 0;
  std::string start_needle;
  start->add_option("--from-row", start_row, "knitting: begin at this row (1 = the first row knitted)")
      ->check(integer_at_least(1));
  start->add_option("--start-needle", start_needle,
                    "knitting: needle of the pattern's leftmost stitch: L20, R5 (the bed's markings) or 30 "
                    "(counted from the left end)")
      ->type_name("NEEDLE");
  std::string start_from;
  start->add_option("--start-from", start_from,
                    "laser: where the job's (0,0) lands: bed (the bed's front-left corner), origin (the work "
                    "zero of `laser origin`) or here (the head's position); default: the job's [laser] start_from, "
                    "else bed")
      ->check(CLI::IsMember({"bed", "origin", "here"}))
      ->type_name("PLACE");
  auto* cancel = app.add_subcommand("cancel", "cancel a job, or with --all every unfinished job");
  auto* cancel_id = cancel->add_option("ID", id, "job id")->check(integer_at_least(1));
  cancel->add_flag("--all", all, "every queued, converting, ready and running job")->excludes(cancel_id);
  auto* retry = app.add_subcommand("retry", "re-queue a failed, interrupted or canceled job");
  add_id(retry);
  auto* resume = app.add_subcommand(
      "resume", "knitting: continue an interrupted job from a row; laser: release a feed hold");
  add_id(resume);
  resume->add_option("--from-row", from_row, "knitting: pattern row to continue from")
      ->check(integer_at_least(1));
  auto* hold = app.add_subcommand("hold", "laser: feed hold (motion stops, beam off)");
  add_id(hold);
  auto* devices = app.add_subcommand("devices", "name, driver, port, state, current job");
  add_json(devices);
  auto* watch = app.add_subcommand("watch", "follow state changes live");
  auto* frame = app.add_subcommand("frame", "laser: trace the job's bounding box, beam off");
  add_id(frame);
  auto* wood = app.add_subcommand("wood", "the workshop's veneer stock (parquetry)");
  wood->require_subcommand(1);
  std::string wood_mask, wood_job;
  double wood_dpi = 0;
  bool wood_force = false;
  auto* wood_list = wood->add_subcommand("list", "veneer sheets: size, usable, used and free wood, jobs");
  add_json(wood_list);
  auto* wood_add = wood->add_subcommand("add", "add a scanned veneer sheet to the wood library");
  wood_add->add_option("IMAGE", file, "scan of the sheet")->required()->check(CLI::ExistingFile);
  wood_add->add_option("--id", wood_id, "sheet id (default: the file's stem)");
  wood_add->add_option("--dpi", wood_dpi, "resolution of the scan (default: [parquetry] dpi)")
      ->check(CLI::PositiveNumber);
  wood_add->add_option("--mask", wood_mask, "mask of the usable veneer (white = usable)")
      ->check(CLI::ExistingFile);
  add_json(wood_add);
  auto* wood_remove = wood->add_subcommand("remove", "remove a sheet from the wood library");
  wood_remove->add_option("ID", wood_id, "sheet id")->required();
  wood_remove->add_flag("--force", wood_force, "even while planned pieces are recorded on it");
  add_json(wood_remove);
  auto* wood_reset = wood->add_subcommand(
      "reset", "forget used wood: of one sheet (ID), of one job (--job), or all");
  wood_reset->add_option("ID", wood_id, "only this sheet");
  wood_reset->add_option("--job", wood_job, "only the pieces of this job")->check(integer_at_least(1));
  add_json(wood_reset);

  auto* laser = app.add_subcommand("laser", "a laser's controller between jobs: unlock, home, jog, origin, console");
  laser->require_subcommand(1);
  std::string laser_device, laser_line;
  double jog_x = 0, jog_y = 0, jog_feed = 0;
  std::int64_t log_lines = 20;
  auto add_device = [&](CLI::App* sub) {
    sub->add_option("--device", laser_device, "the laser device ([[device]] name) when there are several")
        ->type_name("NAME");
  };
  auto* laser_unlock = laser->add_subcommand("unlock", "lift an alarm lock ($X), e.g. after a cancel in motion");
  auto* laser_home = laser->add_subcommand("home", "run the homing cycle ($H)");
  auto* laser_jog = laser->add_subcommand("jog", "move the head by a distance, beam off ($J=)");
  laser_jog->add_option("--x", jog_x, "mm along X (right is positive)")->type_name("MM");
  laser_jog->add_option("--y", jog_y, "mm along Y (towards the rear is positive)")->type_name("MM");
  laser_jog->add_option("--feed", jog_feed, "mm/min (default: the device's frame feed)")
      ->type_name("MM_MIN")
      ->check(CLI::PositiveNumber);
  auto* laser_origin = laser->add_subcommand("origin", "set work zero at the head (G10 L20 P1 X0 Y0)");
  auto* laser_send = laser->add_subcommand("send", "send one line to the controller and print its replies");
  laser_send->add_option("LINE", laser_line, "G-code or a $ command, one line")->required();
  auto* laser_log = laser->add_subcommand("log", "the last lines operators sent and the replies");
  laser_log->add_option("--lines", log_lines, "how many (default 20)")->type_name("N")->check(integer_at_least(1));
  for (CLI::App* sub : {laser_unlock, laser_home, laser_jog, laser_origin, laser_send, laser_log}) {
    add_device(sub);
    add_json(sub);
  }

  // CLI11 calls an unknown verb an unexpected argument: name it as what it is.
  if (const std::string verb = verb_word(argc, argv); !verb.empty()) {
    std::string verbs;
    bool known = false;
    for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
      known = known || sub->get_name() == verb;
      verbs += (verbs.empty() ? "" : ", ") + sub->get_name();
    }
    if (!known) {
      std::cerr << "atelierctl: unknown verb '" << verb << "' (verbs: " << verbs
                << "); see atelierctl --help\n";
      return kExitUsage;
    }
  }
  try {
    app.parse(argc, argv);
    if (cancel->parsed() && id == 0 && !all) throw CLI::ValidationError("cancel", "needs a job ID or --all");
    if (laser_jog->parsed() && jog_x == 0 && jog_y == 0)
      throw CLI::ValidationError("laser jog", "needs a distance: --x MM and/or --y MM");
  } catch (const CLI::ParseError& e) {
    int rc = app.exit(e);  // prints help (rc 0) or the error with a usage hint
    return rc == 0 ? kExitOk : kExitUsage;
  }

  try {
    if (status->parsed()) {
      cmd.verb = "status";
      cmd.render = atelier::ctl::format_status;
    } else if (list->parsed()) {
      cmd.verb = "list";
      if (!state.empty()) {
        if (std::find(atelier::kJobStateNames.begin(), atelier::kJobStateNames.end(), state) ==
            atelier::kJobStateNames.end())
          throw UsageError{"--state " + state + ": unknown state; job states: " + atelier::job_state_list_text()};
        cmd.args["state"] = state;
      }
      if (!kind.empty()) cmd.args["kind"] = kind;  // checked against the daemon's kinds below
      cmd.args["limit"] = all ? 0 : limit > 0 ? limit : 1000;
      cmd.render = atelier::ctl::format_job_table;
    } else if (show->parsed()) {
      cmd = Command{"show", {{"id", id}}, cmd.json_output, atelier::ctl::format_job_details};
    } else if (submit->parsed()) {
      const std::string path = absolute_path(file);
      cmd = Command{"submit", {{"path", path}, {"kind", kind}, {"set", sets}}, false,
                    render_job_or_value, {path}};
    } else if (cancel->parsed() && all) {
      cmd = Command{"cancel", {{"all", true}}, false, atelier::ctl::format_cancel_all};
    } else if (start->parsed() || cancel->parsed() || retry->parsed() || frame->parsed() ||
               hold->parsed()) {
      std::string verb = start->parsed()    ? "start"
                         : cancel->parsed() ? "cancel"
                         : retry->parsed()  ? "retry"
                         : hold->parsed()   ? "hold"
                                            : "frame";
      json verb_args = {{"id", id}};
      if (start->parsed() && start_row > 0) verb_args["from_row"] = start_row;
      if (start->parsed() && !start_needle.empty()) verb_args["start_needle"] = start_needle;
      if (start->parsed() && !start_from.empty()) verb_args["start_from"] = start_from;
      cmd = Command{verb, verb_args, false, render_job_or_value};
    } else if (resume->parsed()) {
      json resume_args = {{"id", id}};
      if (from_row > 0) resume_args["from_row"] = from_row;
      cmd = Command{"resume", resume_args, false, render_job_or_value};
    } else if (laser->parsed()) {
      cmd.verb = "laser";
      cmd.render = atelier::ctl::format_laser;
      const std::string action = laser_unlock->parsed() ? "unlock"
                                 : laser_home->parsed() ? "home"
                                 : laser_jog->parsed()  ? "jog"
                                 : laser_origin->parsed() ? "origin"
                                 : laser_send->parsed()   ? "send"
                                                          : "log";
      cmd.args = {{"action", action}};
      if (!laser_device.empty()) cmd.args["device"] = laser_device;
      if (laser_jog->parsed()) {
        cmd.args["x"] = jog_x;
        cmd.args["y"] = jog_y;
        if (jog_feed > 0) cmd.args["feed"] = jog_feed;
      }
      if (laser_send->parsed()) cmd.args["line"] = laser_line;
      if (laser_log->parsed()) cmd.args["limit"] = log_lines;
    } else if (devices->parsed()) {
      cmd.verb = "devices";
      cmd.render = atelier::ctl::format_devices;
    } else if (wood->parsed()) {
      cmd.verb = "wood";
      cmd.render = atelier::ctl::format_wood;
      if (wood_list->parsed()) {
        cmd.args = {{"action", "list"}};
      } else if (wood_add->parsed()) {
        cmd.args = {{"action", "add"}, {"image", absolute_path(file)}};
        cmd.files = {cmd.args["image"]};
        if (!wood_id.empty()) cmd.args["id"] = wood_id;
        if (wood_dpi > 0) cmd.args["dpi"] = wood_dpi;
        if (!wood_mask.empty()) {
          cmd.args["mask"] = absolute_path(wood_mask);
          cmd.files.push_back(cmd.args["mask"]);
        }
      } else if (wood_remove->parsed()) {
        cmd.args = {{"action", "remove"}, {"id", wood_id}, {"force", wood_force}};
      } else if (wood_reset->parsed()) {
        cmd.args = {{"action", "reset"}};
        if (!wood_id.empty()) cmd.args["id"] = wood_id;
        if (!wood_job.empty()) cmd.args["job"] = wood_job;
      }
    }
  } catch (const std::filesystem::filesystem_error& e) {
    std::cerr << "atelierctl: cannot resolve " << file << ": " << e.code().message() << "\n";
    return kExitUsage;
  } catch (const UsageError& e) {
    std::cerr << "atelierctl: " << e.message << "\n";
    return kExitUsage;
  }

  // The daemon reads these with our rights, not its own: we open them and pass the descriptors.
  std::vector<int> open_files;
  struct CloseAll {
    std::vector<int>& fds;
    ~CloseAll() {
      for (int fd : fds) ::close(fd);
    }
  } close_all{open_files};
  try {
    for (const std::string& f : cmd.files) open_files.push_back(atelier::ctl::open_regular_file(f));
  } catch (const std::runtime_error& e) {
    std::cerr << "atelierctl: " << e.what() << "\n";
    return kExitFailed;
  }

  try {
    if (watch->parsed()) return run_watch(socket);
    ControlClient client(socket);
    if (list->parsed() && !kind.empty()) {
      // The kinds are the daemon's: this build's registry, which the client does not link.
      json status = client.request("status", json::object());
      if (!response_ok(status)) return print_failure(status);
      const json kinds = status["result"].value("kinds", json::array());
      if (std::find(kinds.begin(), kinds.end(), kind) == kinds.end()) {
        std::string names;
        for (const json& k : kinds) names += (names.empty() ? "" : ", ") + k.get<std::string>();
        std::cerr << "atelierctl: --kind " << kind << ": unknown kind; this daemon converts: " << names << "\n";
        return kExitUsage;
      }
    }
    // Homing takes up to a minute on the machine, after the controller's setup.
    const auto timeout = laser->parsed() ? std::chrono::milliseconds(200000) : ControlClient::kDefaultTimeout;
    json response = client.request(cmd.verb, cmd.args, timeout, open_files);
    if (!response_ok(response)) return print_failure(response);
    json result = response.contains("result") ? response["result"] : json();
    result = settled(client, result);
    if (list->parsed()) {
      // {"jobs": [...], "total": N}; an older daemon answered the array alone.
      json jobs = result.is_object() ? result.value("jobs", json::array()) : result;
      if (std::string note = atelier::ctl::list_cut_note(result); !note.empty()) std::cerr << note;
      result = std::move(jobs);
    }
    if (cmd.json_output) {
      std::cout << result.dump(2, ' ', false, json::error_handler_t::replace) << "\n";
    } else {
      std::cout << cmd.render(result);
    }
    return kExitOk;
  } catch (const atelier::ctl::UnreachableError& e) {
    print_unreachable(e);
    return kExitUnreachable;
  } catch (const atelier::ctl::ProtocolError& e) {
    std::cerr << "atelierctl: " << e.what() << "\n";
    return kExitFailed;
  }
}
