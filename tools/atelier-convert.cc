// atelier-convert: one job's conversion without the daemon (the daemon runs it as a child).
//
//   atelier-convert KIND INPUT OUTPUT_DIR [--params FILE.toml] [--set key=value ...]
//                   [--with INPUT2 OUTPUT_DIR2 ...] [--progress-fd N] [--max-file-bytes B]
//                   [--max-pixels P] [--check] [--memory-mb N] [--confine DIR ...]
//
// --check only parses and checks the parameters (--params, then --set), reads no input and
// writes nothing; atelierd runs it to refuse a submit's bad --set values in a child process.
//
// --with (repeatable; parquetry only) plans another target together with INPUT on the same
// wood, in one priority queue (paper 4.2): each target gets its own outputs in its own folder
// and its own label in the stock (the folder's name). A target's sidecar is not read for --with
// targets: they share INPUT's parameters.
//
// Parameters are layered: --params (the daemon's merged defaults), then `<INPUT>.toml` beside
// the input when it exists (the sidecar, as in the hot folder), then each --set. For lace,
// INPUT is the job file itself (NAME.toml: kind = "lace" and parameters), the middle layer,
// or "-" for none. Writes the
// kind's outputs and a copy of the input into OUTPUT_DIR, like a job's done/<id>/ folder.
// --confine (repeatable; atelierd passes the spool and [spool] allow_paths): a path that the
// sidecar, the job file or --set gives (relax_mask, start_chart, wood, pencil, textures) must
// lie inside one of these folders and is opened without following any symlink; a job may not
// set `stock`. Paths from --params (the daemon's config) are opened as given, as is everything
// without --confine (convert/common/job_paths.h).
// Exit codes: 0 ok, 1 bad input or parameters (message on stderr), 2 usage.
//
// Two more commands that are not job kinds (they take their own options; see `--help` of each):
//   atelier-convert line - OUTPUT_DIR --set from=X,Y --set to=X,Y [--set pencil=6B] [--set ...]
//       one hand-drawn pencil line: line.png, line.json, report.json (tools/convert_commands.h)
//   atelier-convert pencil-profile SCAN.png OUT.toml [--set name=6B] [--set paper_threshold=245]
//   atelier-convert pencil-profile --reference GRADE OUT.toml [--scan-png SCAN.png]
//       learn a pencil profile from a scan of pencil lines running vertically on white paper, or
//       from the modelled reference scan of a shipped grade (tools/make-pencil-profiles)
//   atelier-convert --list-kinds
//       prints the kinds this build converts, one a line (the registry, convert/kinds.h), for
//       atelierctl's shell completion (tools/completion/atelierctl)
//   atelier-convert --job-kind FILE
//       prints the kind a job file names (the daemon asks this in a child: untrusted TOML is
//       never parsed inside atelierd; convert/job_file_kind.h)
//   atelier-convert --decode-check IMAGE...
//       decodes each image (with the default limits) and exits 0, or 1 naming the file that
//       does not decode (atelierd checks scans handed to `wood add` so: daemon/scan_check.h)
#include <CLI/CLI.hpp>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "base/cli_parse.h"
#include "convert/convert.h"
#include "convert/common/job_start.h"
#include "convert/kinds.h"
#include "convert/common/memory_budget.h"
#include "convert/common/display_text.h"
#include "convert/common/image_input.h"
#include "convert/common/job_paths.h"
#include "convert/common/param_table.h"
#include "convert/job_file_kind.h"
#include "tools/convert_commands.h"

namespace fs = std::filesystem;
using atelier::ConvertError;
using atelier::ParamError;

namespace {

using atelier::convert_tool::parse_toml_file;

// Reports progress to the daemon (a "progress F" line per percent on a pipe) and, on a
// terminal, as a bar once the work has run for more than a second.
class Progress {
 public:
  Progress(int fd, std::string label) : fd_(fd), label_(std::move(label)), tty_(isatty(2)) {}
  ~Progress() {
    if (bar_shown_) std::fprintf(stderr, "\r\033[K");
  }

  void operator()(double f) {
    int percent = static_cast<int>(f * 100 + 0.5);
    if (percent == last_percent_) return;
    last_percent_ = percent;
    if (fd_ >= 0) {
      char line[32];
      int n = std::snprintf(line, sizeof line, "progress %.2f\n", f);
      ssize_t ignored = ::write(fd_, line, static_cast<size_t>(n));  // daemon gone: no matter
      (void)ignored;
    }
    if (tty_ && std::chrono::steady_clock::now() - start_ > std::chrono::seconds(1)) {
      const int width = 30;
      int filled = percent * width / 100;
      std::fprintf(stderr, "\r[%s%s] %3d%% %s", std::string(filled, '#').c_str(),
                   std::string(width - filled, ' ').c_str(), percent, label_.c_str());
      std::fflush(stderr);
      bar_shown_ = true;
    }
  }

 private:
  int fd_;
  std::string label_;
  bool tty_;
  bool bar_shown_ = false;
  int last_percent_ = -1;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

// The copy of the input that a done/<job-id>/ folder holds. Skipped when the input already
// lives in the output folder; renamed when its name would clash with an output file.
void copy_input(const fs::path& input, const fs::path& out_dir,
                const std::vector<std::string>& outputs) {
  std::error_code ec;
  if (fs::equivalent(input.parent_path().empty() ? "." : input.parent_path(), out_dir, ec)) return;
  std::string name = input.filename().string();
  for (const auto& o : outputs)
    if (o == name) name = "input-" + name;
  fs::copy_file(input, out_dir / name, fs::copy_options::overwrite_existing, ec);
  // A read-only source must not make the copy read-only: a rerun overwrites it.
  if (!ec) fs::permissions(out_dir / name, fs::perms::owner_write, fs::perm_options::add, ec);
  if (ec) throw ConvertError(name + ": cannot copy into " + out_dir.string() + ": " + ec.message());
}

// A reason names the job's file: one about a --set value (or another file) gets the input's
// name in front, so the reason of a job says which job it is.
std::string naming_input(const std::string& input, const std::string& message) {
  if (input == "-") return message;
  const std::string name = atelier::display_name(input);
  if (message.find(name) != std::string::npos) return message;
  return name + ": " + message;
}

}  // namespace

int main(int argc, char** argv) {
  std::signal(SIGPIPE, SIG_IGN);  // a vanished daemon must not kill a conversion mid-write

  // Not job kinds: commands with their own options (and --help).
  if (argc >= 2 && std::string(argv[1]) == "line") return atelier::convert_tool::run_line(argc - 1, argv + 1);
  if (argc >= 2 && std::string(argv[1]) == "pencil-profile") return atelier::convert_tool::run_pencil_profile(argc - 1, argv + 1);
  // Before CLI11: its version flag does not win over the required positionals.
  if (argc == 2 && std::string(argv[1]) == "--version") {
    std::cout << "atelier-convert " ATELIER_VERSION "\n";
    return 0;
  }
  if (argc == 2 && std::string(argv[1]) == "--list-kinds") {
    for (const std::string& k : atelier::known_kinds()) std::cout << k << "\n";
    return 0;
  }
  if (argc == 3 && std::string(argv[1]) == "--job-kind") {
    const auto found = atelier::read_job_file_kind(argv[2], fs::path(argv[2]).filename().string());
    if (!found.problem.empty()) {
      std::cerr << "error: " << found.problem << "\n";
      return 1;
    }
    std::cout << found.kind << "\n";
    return 0;
  }

  if (argc >= 3 && std::string(argv[1]) == "--decode-check") {
    for (int i = 2; i < argc; ++i) {
      try {
        atelier::load_image(argv[i], atelier::ImageLimits{});
      } catch (const std::exception& e) {
        std::cerr << "error: " << e.what() << "\n";
        return 1;
      }
    }
    return 0;
  }

  CLI::App app{"atelier-convert: convert one input file as an atelier job would.\n"
               "Also: `atelier-convert line - OUTPUT_DIR --set from=X,Y --set to=X,Y --set pencil=6B` (one\n"
               "hand-drawn pencil line) and `atelier-convert pencil-profile SCAN.png OUT.toml` (learn a\n"
               "pencil from a scan of its lines); run either with --help."};
  std::string kind, input, output_dir, params_file;
  std::vector<std::string> sets;
  std::vector<std::vector<std::string>> with;
  int progress_fd = -1;
  std::vector<std::string> confine;
  atelier::ImageLimits limits;
  app.add_option("KIND", kind,
                 "kind of job (knit, parquetry, embroidery, sketch: an image; cut: an SVG; lace: a job "
                 "file NAME.toml or -); or the "
                 "commands line and pencil-profile, given first (see their --help)")
      ->required();
  app.add_option("INPUT", input, "input file (\"-\": none, for lace)")->required();
  app.add_option("OUTPUT_DIR", output_dir, "folder for the outputs (created if missing)")
      ->required();
  app.add_option("--params", params_file, "TOML file of parameters (applied first)");
  app.add_option("--set", sets, "override one parameter, key=value (repeatable)")
      ->allow_extra_args(false);
  app.add_option("--with", with, "another target planned together: INPUT OUTPUT_DIR (parquetry; repeatable)")
      ->expected(2)
      ->allow_extra_args(false)
      ->take_all();
  app.add_option("--progress-fd", progress_fd, "write \"progress F\" lines to this fd")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--max-file-bytes", limits.max_file_bytes, "largest input file in bytes");
  app.add_option("--max-pixels", limits.max_pixels, "largest input image in pixels");
  app.set_version_flag("--version", "atelier-convert " ATELIER_VERSION, "print \"atelier-convert VERSION\" and exit");
  bool check_only = false;
  app.add_flag("--check", check_only,
               "only parse and check --params and --set (INPUT and OUTPUT_DIR are not read; give -)");
  uint64_t memory_mb = 0;
  app.add_option("--memory-mb", memory_mb,
                 "memory budget in MB (address-space limit; 0: none); running out fails with "
                 "\"INPUT: needs more than N MB (limits.job_memory_mb)\"");
  app.add_option("--confine", confine,
                 "files named by the sidecar, job file or --set must be inside DIR (repeatable)")
      ->allow_extra_args(false);
  if (auto stop = atelier::parse_command_line(app, argc, argv)) return *stop;
  for (const auto& w : with) {
    if (w.size() != 2) {
      std::cerr << "error: --with takes two values: INPUT OUTPUT_DIR\n"
                << "Run with --help for more information.\n";
      return 2;
    }
  }
  if (kind == "line" || kind == "pencil-profile") {
    std::cerr << "error: '" << kind << "' is a command, not a kind: put it first (atelier-convert " << kind
              << " --help)\n";
    return 2;
  }
  if (!atelier::is_known_kind(kind)) {
    std::cerr << "error: unknown kind '" << kind << "' (known kinds: " << atelier::known_kinds_text() << ")\n"
              << "Run with --help for more information.\n";
    return 2;
  }

  const std::string input_name = fs::path(input).filename().string();
  try {
    if (memory_mb > 0) atelier::apply_memory_budget(memory_mb, input_name);
    // Each layer is checked on its own first, so an error names its file and line.
    toml::table params;
    std::vector<fs::path> roots(confine.begin(), confine.end());
    atelier::JobPaths paths(roots);
    // Every key a job layer sets is the job's: its paths are confined (and named by its file).
    auto mark = [&paths](const toml::table& layer, const std::string& source, const fs::path& base) {
      for (const auto& [k, v] : layer) paths.mark_from_job(std::string(k.str()), source, base);
    };
    // A knitting job's own file may say how it starts on the machine (autostart, start_row,
    // start_needle: convert/common/job_start.h); atelierd reads those, the conversion does not.
    const std::vector<std::string> knitted = atelier::kinds_for_driver(atelier::kAyabDriver);
    const bool knitted_kind = std::find(knitted.begin(), knitted.end(), kind) != knitted.end();
    auto take_start_keys = [knitted_kind](toml::table& layer, const std::string& source) {
      if (knitted_kind) atelier::take_job_start(layer, source);
    };
    if (!params_file.empty()) {
      toml::table layer = parse_toml_file(params_file);
      atelier::validate_kind_params(kind, layer, params_file);
      atelier::merge_into(params, layer);
    }
    if (check_only) {
      // atelierd checks a submit's --set values here, in a child: TOML is parsed where a crash
      // costs nothing but the check.
      toml::table overrides;
      for (const auto& s : sets) atelier::apply_set(overrides, s);
      atelier::validate_kind_params(kind, overrides, "--set");
      atelier::merge_into(params, overrides);
      atelier::validate_kind_params(kind, params, "--set");
      return 0;
    }
    fs::path in(input);
    const bool no_input = input == "-";
    std::error_code ec;
    if (atelier::converts_job_file(kind)) {
      // The job file is the kind's parameters (and `kind`); "-" is no file at all.
      if (no_input) {
      } else if (in.extension() != ".toml") {
        throw ConvertError(in.filename().string() + ": a " + kind + " job is a TOML job file of "
                           "parameters (NAME.toml), not an image");
      } else {
        toml::table layer = parse_toml_file(in.string());
        take_start_keys(layer, in.string());
        atelier::validate_kind_params(kind, layer, in.string());
        mark(layer, in.string(), in.parent_path());
        atelier::merge_into(params, layer);
      }
    } else if (no_input) {
      throw ConvertError("'-' (no input file) is only for job-file kinds such as lace; " + kind +
                         " needs an input file");
    } else {
      fs::path sidecar = in;
      sidecar += ".toml";
      if (in.extension() != ".toml" && fs::is_regular_file(sidecar, ec)) {
        toml::table layer = parse_toml_file(sidecar.string());
        take_start_keys(layer, sidecar.string());
        atelier::validate_kind_params(kind, layer, sidecar.string());
        mark(layer, sidecar.string(), sidecar.parent_path());
        atelier::merge_into(params, layer);
      }
    }
    toml::table overrides;
    for (const auto& s : sets) atelier::apply_set(overrides, s);
    atelier::validate_kind_params(kind, overrides, "--set");
    mark(overrides, "--set", {});
    atelier::merge_into(params, overrides);

    Progress progress(progress_fd, in.filename().string());
    atelier::ConvertRequest req;
    req.kind = kind;
    req.input = in;
    req.params = std::move(params);
    req.params_source = "parameters";
    req.output_dir = output_dir;
    req.limits = limits;
    req.memory_mb = memory_mb;
    req.paths = std::move(paths);
    for (const auto& w : with) req.together.push_back({w.at(0), w.at(1)});
    req.progress = [&progress](double f) { progress(f); };
    atelier::ConvertResult result = atelier::convert(req);
    if (!no_input) copy_input(in, output_dir, result.outputs);
    for (const auto& extra : req.together) {
      // Each target's folder holds its own input, like a job's done/<id>/ folder.
      copy_input(extra.input, extra.output_dir, result.outputs);
    }
  } catch (const std::exception& e) {
    if (atelier::is_out_of_memory(e)) {
      // An allocation beyond the budget: say so, not "std::bad_alloc".
      std::cerr << "error: "
                << (memory_mb > 0 ? atelier::memory_exceeded_reason(input_name, memory_mb)
                                  : input_name + ": out of memory (" + e.what() + ")")
                << "\n";
    } else if (dynamic_cast<const ConvertError*>(&e) || dynamic_cast<const ParamError*>(&e)) {
      std::cerr << "error: " << naming_input(input, e.what()) << "\n";
    } else {
      std::cerr << "error: " << atelier::display_path(input) << ": " << e.what() << "\n";
    }
    return 1;
  }
  return 0;
}
