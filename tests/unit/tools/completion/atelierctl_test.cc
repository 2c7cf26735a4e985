// The bash completion of atelierctl (tools/completion/atelierctl), as bash runs it on TAB: a
// bash sources bash-completion and the script, fills COMP_WORDS as for the typed line and calls
// the completion function; the test reads COMPREPLY. The programs it asks are the built ones
// (build/bin first on PATH), and the job ids come from a real atelierd.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "convert/kinds.h"
#include "daemon/store.h"
#include "tests/e2e/daemon_harness.h"
#include "tests/support/cli_help.h"

namespace {

namespace fs = std::filesystem;
using atelier::test::binary;
using atelier::test::run_command;
using Words = std::set<std::string>;

const fs::path kCompletion = fs::path(ATELIER_SOURCE_DIR) / "tools" / "completion" / "atelierctl";
const char* kBashCompletion = "/usr/share/bash-completion/bash_completion";

class Completion : public ::testing::Test {
 protected:
  // What TAB offers after `line` (the words typed; the last is the one being completed, "" for
  // a fresh word), with $ATELIER_SOCKET = `socket`. `with_bash_completion`: source the
  // bash-completion library first, as an interactive shell has it.
  Words complete(const std::vector<std::string>& line, const std::string& socket = "/nonexistent/control.sock",
                 bool with_bash_completion = true) {
    const fs::path driver = tmp_.path() / "complete.sh";
    atelier::test::write_file(
        driver,
        std::string(with_bash_completion ? "source " + std::string(kBashCompletion) + " || exit 9\n" : "") +
            "source \"$1\" || exit 9\n"
            "export PATH=\"$2:$PATH\" ATELIER_SOCKET=\"$3\"\n"
            "shift 3\n"
            "COMP_WORDS=(\"$@\"); COMP_CWORD=$(($# - 1)); COMP_LINE=\"$*\"; COMP_POINT=${#COMP_LINE}\n"
            "_atelierctl \"$1\" \"${COMP_WORDS[COMP_CWORD]}\" \"${COMP_WORDS[COMP_CWORD - 1]}\"\n"
            "printf '%s\\n' \"${COMPREPLY[@]}\"\n");
    std::vector<std::string> argv = {"/bin/bash", driver.string(), kCompletion.string(),
                                     binary("atelierctl").parent_path().string(), socket};
    argv.insert(argv.end(), line.begin(), line.end());
    const auto run = run_command(argv);
    EXPECT_EQ(run.exit_code, 0) << "bash " << driver << ": " << run.err;
    Words offered;
    std::istringstream out(run.out);
    for (std::string w; std::getline(out, w);)
      if (!w.empty()) offered.insert(w);
    return offered;
  }

  static atelier::test::CliHelp help(std::vector<std::string> args) {
    args.insert(args.begin(), binary("atelierctl").string());
    args.push_back("--help");
    return atelier::test::parse_cli_help(run_command(args).out);
  }
  static Words long_options(const atelier::test::CliHelp& h) {
    Words out;
    for (const std::string& o : h.options)
      if (o.rfind("--", 0) == 0) out.insert(o);
    return out;
  }

  atelier::test::TempDir tmp_;
};

TEST_F(Completion, OffersTheVerbsAtelierctlHas) {
  const Words verbs = help({}).subcommands;
  ASSERT_TRUE(verbs.count("list") && verbs.count("wood")) << "atelierctl --help lists no verbs";
  EXPECT_EQ(complete({"atelierctl", ""}), verbs);
  EXPECT_EQ(complete({"atelierctl", "st"}), (Words{"start", "status"}));
  // After --socket PATH the verb is still to come.
  EXPECT_EQ(complete({"atelierctl", "--socket", "/run/x.sock", ""}), verbs);
  EXPECT_EQ(complete({"atelierctl", "wood", ""}), help({"wood"}).subcommands);
}

TEST_F(Completion, OffersEachVerbsOwnOptionsAndTheSocket) {
  for (const std::string& verb : help({}).subcommands) {
    const auto verb_help = help({verb});
    std::vector<std::vector<std::string>> lines = {{verb}};
    for (const std::string& sub : verb_help.subcommands) lines.push_back({verb, sub});
    for (const auto& words : lines) {
      std::vector<std::string> line = {"atelierctl"};
      line.insert(line.end(), words.begin(), words.end());
      line.push_back("-");
      Words want = long_options(help(words));
      if (words.size() == 1 && !verb_help.subcommands.empty()) {
        EXPECT_EQ(complete(line), want) << line[1];
        continue;
      }
      want.insert("--socket");  // it may follow the verb
      EXPECT_EQ(complete(line), want) << line[1] << " " << (words.size() > 1 ? words[1] : "");
    }
  }
  EXPECT_TRUE(complete({"atelierctl", "list", "--"}).count("--state"));
}

TEST_F(Completion, OffersTheRegistrysKindsAfterKind) {
  const std::vector<std::string>& kinds = atelier::known_kinds();
  const Words all(kinds.begin(), kinds.end());
  EXPECT_EQ(complete({"atelierctl", "list", "--kind", ""}), all);
  EXPECT_EQ(complete({"atelierctl", "submit", "photo.jpg", "--kind", ""}), all);
  const std::string first = kinds.front();
  EXPECT_TRUE(complete({"atelierctl", "list", "--kind", first.substr(0, 2)}).count(first));
}

TEST_F(Completion, OffersEveryJobStateAfterState) {
  Words states;
  for (int s = 0; s <= static_cast<int>(atelier::JobState::interrupted); ++s)
    states.insert(atelier::state_name(static_cast<atelier::JobState>(s)));
  EXPECT_EQ(complete({"atelierctl", "list", "--state", ""}), states);
  // Also with no bash-completion library loaded (the script sourced by hand).
  EXPECT_EQ(complete({"atelierctl", "list", "--state", ""}, "/nonexistent/control.sock", false), states);
  for (const std::string& s : complete({"atelierctl", "list", "--state", ""}))
    EXPECT_TRUE(atelier::state_from_name(s)) << s << " is not a job state";
}

const atelier::KindInfo& image_kind() {
  for (const atelier::KindInfo& k : atelier::kinds())
    if (k.input == atelier::KindInput::image) return k;
  throw std::runtime_error("no kind converts an image");
}

TEST_F(Completion, OffersTheDaemonsJobIdsInTheStatesTheVerbTakesAndItsVeneerSheets) {
  fs::create_directories(tmp_.path() / "d");
  atelier::test::DaemonProcess daemon(tmp_.path() / "d");
  daemon.start();
  const std::string kind(image_kind().name);
  // One job that fails (not an image) and one that completes (no device takes the kind).
  atelier::test::write_file(tmp_.path() / "broken.png", "not a picture");
  atelier::test::drop_file(tmp_.path() / "broken.png", daemon.incoming(kind) / "broken.png");
  ASSERT_TRUE(daemon.wait_job_state("broken.png", "failed")) << daemon.log();
  atelier::test::drop_file(atelier::test::test_image("pic1.png"), daemon.incoming(kind) / "pic1.png");
  ASSERT_TRUE(daemon.wait_job_state("pic1.png", "completed")) << daemon.log();
  const std::string failed = std::to_string(daemon.job_named("broken.png")["id"].get<int64_t>());
  const std::string completed = std::to_string(daemon.job_named("pic1.png")["id"].get<int64_t>());
  const std::string socket = daemon.socket().string();

  EXPECT_EQ(complete({"atelierctl", "show", ""}, socket), (Words{failed, completed}));
  EXPECT_EQ(complete({"atelierctl", "retry", ""}, socket), (Words{failed}));
  EXPECT_EQ(complete({"atelierctl", "start", ""}, socket), Words{});  // nothing is ready
  EXPECT_EQ(complete({"atelierctl", "wood", "reset", "--job", ""}, socket), (Words{failed, completed}));
  // Only the verb's first argument is a job.
  EXPECT_EQ(complete({"atelierctl", "show", failed, ""}, socket), Words{});
  // The daemon the line names with --socket, not $ATELIER_SOCKET's.
  EXPECT_EQ(complete({"atelierctl", "--socket", socket, "retry", ""}), (Words{failed}));
  EXPECT_EQ(complete({"atelierctl", "retry", "--socket", socket, ""}), (Words{failed}));

  const auto added = run_command({binary("atelierctl").string(), "--socket", socket, "wood", "add",
                                  atelier::test::test_image("wood/maple_light.png").string(), "--dpi", "300"});
  ASSERT_EQ(added.exit_code, 0) << added.err;
  EXPECT_EQ(complete({"atelierctl", "wood", "remove", ""}, socket), (Words{"maple_light"}));
  EXPECT_EQ(complete({"atelierctl", "wood", "reset", ""}, socket), (Words{"maple_light"}));
}

TEST_F(Completion, OffersNoJobsAndReturnsWhenTheDaemonIsGoneOrDoesNotAnswer) {
  EXPECT_EQ(complete({"atelierctl", "show", ""}, (tmp_.path() / "gone.sock").string()), Words{});
  // A socket that takes the connection and never answers: the query is given up.
  const std::string silent = (tmp_.path() / "silent.sock").string();
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::snprintf(address.sun_path, sizeof address.sun_path, "%s", silent.c_str());
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address), 0) << std::strerror(errno);
  ASSERT_EQ(::listen(fd, 8), 0);
  EXPECT_EQ(complete({"atelierctl", "cancel", ""}, silent), Words{});
  EXPECT_EQ(complete({"atelierctl", "wood", "remove", ""}, silent), Words{});
  ::close(fd);
}

}  // namespace
