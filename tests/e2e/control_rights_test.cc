// The real daemon acts with its clients' rights, not its own: `submit` and `wood add` read
// the file the client opened and passed (SCM_RIGHTS), a raw path from another uid is refused,
// --set values are checked in a converter child (a crash there costs only the submit), and
// outputs are not world-readable (umask 0027).
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "tests/e2e/daemon_harness.h"
#include "tests/support/foreign_user.h"
#include "tools/ctl_client.h"

namespace {

namespace fs = std::filesystem;
using atelier::test::DaemonProcess;
using atelier::test::TempDir;
using nlohmann::json;

const std::string kCtl = atelier::test::binary("atelierctl").string();

// A daemon whose socket and folders other users can reach, as group members would.
struct OpenDaemon {
  TempDir tmp;
  DaemonProcess daemon;
  explicit OpenDaemon(const std::string& extra = "[limits]\nworkers = 1\n[knit]\nwidth = 40\n")
      : daemon(tmp.path(), extra) {
    ::chmod(tmp.path().c_str(), 0755);
  }
  void start() {
    daemon.start();
    ::chmod(daemon.socket().c_str(), 0666);
  }
  std::string socket() const { return daemon.socket().string(); }
};

// A folder in /tmp anyone can read, holding a copy of a test image.
fs::path public_copy(const TempDir& dir, const std::string& image, const std::string& name) {
  ::chmod(dir.path().c_str(), 0755);
  const fs::path p = dir.path() / name;
  fs::copy_file(atelier::test::test_image(image), p, fs::copy_options::overwrite_existing);
  ::chmod(p.c_str(), 0644);
  return p;
}

// A raw request from nobody that names a path and passes no descriptor.
json raw_request_as_nobody(const std::string& socket, const std::string& verb, const json& args) {
  auto run = atelier::test::in_child_as_nobody([&](int out) {
    atelier::ctl::ControlClient client(socket);
    const std::string line = client.request(verb, args).dump() + "\n";
    return ::write(out, line.data(), line.size()) > 0 ? 0 : 1;
  });
  if (run.exit_code != 0) return {{"child_failed", run.err}};
  return json::parse(run.out);
}

void expect_not_world_readable(const fs::path& p) {
  struct stat st {};
  ASSERT_EQ(::stat(p.c_str(), &st), 0) << p;
  EXPECT_EQ(st.st_mode & 0007, 0u) << p << " is open to everyone: " << std::oct << (st.st_mode & 0777);
  EXPECT_EQ(st.st_mode & 0022, 0u) << p << " is writable by others";
}

TEST(E2ERights, SubmitReadsTheFileTheClientOpenedAndRefusesWhatItCannotRead) {
  OpenDaemon d;
  d.start();
  TempDir files;  // in /tmp, which used to be out of reach under the unit's PrivateTmp
  const fs::path cat = public_copy(files, "pic1.png", "cat.png");
  const fs::path secret = files.path() / "secret.png";
  fs::copy_file(atelier::test::test_image("pic3.png"), secret);
  ::chmod(secret.c_str(), 0600);

  // nobody cannot open the root-only file, so atelierctl cannot submit it.
  auto denied = atelier::test::run_as_nobody(
      {kCtl, "--socket", d.socket(), "submit", secret.string(), "--kind", "knit"});
  EXPECT_EQ(denied.exit_code, 1) << denied.err;
  EXPECT_NE(denied.err.find("Permission denied"), std::string::npos) << denied.err;
  // Nor by naming the path over the raw socket: the daemon opens no path for another uid.
  json raw = raw_request_as_nobody(d.socket(), "submit", {{"path", secret.string()}, {"kind", "knit"}});
  EXPECT_FALSE(raw.value("ok", true)) << raw;
  EXPECT_NE(raw.value("error", "").find("submit passes the open file; use atelierctl submit"),
            std::string::npos)
      << raw;
  // Not even a file nobody could read: the rule is the descriptor, not a guess at rights.
  raw = raw_request_as_nobody(d.socket(), "submit", {{"path", cat.string()}, {"kind", "knit"}});
  EXPECT_FALSE(raw.value("ok", true)) << raw;
  EXPECT_TRUE(d.daemon.jobs().empty()) << d.daemon.jobs();

  // The file nobody can read, passed by atelierctl as an open file: a job.
  auto ok = atelier::test::run_as_nobody({kCtl, "--socket", d.socket(), "submit", cat.string(), "--kind", "knit"});
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  ASSERT_TRUE(d.daemon.wait_job_state("cat.png", "completed")) << d.daemon.jobs() << d.daemon.log();
  // Root's own raw path request (same rights as the daemon's) still works.
  json own = d.daemon.request("submit", {{"path", secret.string()}, {"kind", "knit"}});
  ASSERT_TRUE(own.value("ok", false)) << own;
  ASSERT_TRUE(d.daemon.wait_job_state("secret.png", "completed")) << d.daemon.jobs();

  // The outputs are the group's, not the world's: files 0640, folders 0750.
  const fs::path out = d.daemon.job_named("cat.png")["output_dir"].get<std::string>();
  expect_not_world_readable(out);
  expect_not_world_readable(out.parent_path());  // done/
  int files_seen = 0;
  for (const auto& e : fs::directory_iterator(out)) {
    expect_not_world_readable(e.path());
    ++files_seen;
  }
  EXPECT_GE(files_seen, 5);
  expect_not_world_readable(d.daemon.spool() / "work");
  expect_not_world_readable(d.tmp.path() / "jobs.sqlite");
  EXPECT_EQ(d.daemon.stop(SIGTERM), 0);
}

TEST(E2ERights, WoodAddCopiesOnlyWhatTheClientCanRead) {
  OpenDaemon d;
  d.start();
  TempDir files;
  const fs::path oak = public_copy(files, "pic5.png", "oak.png");
  const fs::path secret = files.path() / "private.png";
  fs::copy_file(atelier::test::test_image("pic3.png"), secret);
  ::chmod(secret.c_str(), 0600);

  auto denied = atelier::test::run_as_nobody({kCtl, "--socket", d.socket(), "wood", "add", secret.string()});
  EXPECT_EQ(denied.exit_code, 1) << denied.err;
  json raw = raw_request_as_nobody(d.socket(), "wood", {{"action", "add"}, {"image", secret.string()}});
  EXPECT_FALSE(raw.value("ok", true)) << raw;
  EXPECT_NE(raw.value("error", "").find("wood passes the open file"), std::string::npos) << raw;

  auto ok = atelier::test::run_as_nobody({kCtl, "--socket", d.socket(), "wood", "add", oak.string(), "--json"});
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  json list = d.daemon.request("wood", {{"action", "list"}});
  ASSERT_TRUE(list.value("ok", false)) << list;
  std::vector<std::string> ids;
  for (const auto& s : list["result"]["sheets"]) ids.push_back(s["id"]);
  EXPECT_EQ(ids, std::vector<std::string>{"oak"});
  for (const auto& e : fs::recursive_directory_iterator(d.tmp.path()))
    EXPECT_EQ(e.path().filename().string().find("private"), std::string::npos) << e.path();
  EXPECT_EQ(d.daemon.stop(SIGTERM), 0);
}

TEST(E2ERights, SetValuesAreCheckedInAChildSoACrashCostsOnlyTheSubmit) {
  OpenDaemon d;
  // A converter that crashes whenever it checks parameters, as a TOML parser bug would.
  const fs::path crashing = d.tmp.path() / "crashing-convert";
  {
    std::ofstream script(crashing);
    script << "#!/bin/sh\nfor a in \"$@\"; do [ \"$a\" = --check ] && kill -SEGV $$; done\nexec "
           << atelier::test::binary("atelier-convert").string() << " \"$@\"\n";
  }
  ::chmod(crashing.c_str(), 0755);
  d.daemon.set_env({"ATELIER_CONVERT=" + crashing.string()});
  d.start();
  const std::string pic = atelier::test::test_image("pic1.png").string();
  json r = d.daemon.request("submit", {{"path", pic}, {"kind", "knit"}, {"set", {"width=50"}}});
  EXPECT_FALSE(r.value("ok", true)) << r;
  EXPECT_NE(r.value("error", "").find("signal 11"), std::string::npos) << r;
  EXPECT_TRUE(d.daemon.request("status").value("ok", false)) << "the daemon died with the check";
  EXPECT_TRUE(d.daemon.jobs().empty());
  EXPECT_EQ(d.daemon.stop(SIGTERM), 0);
}

TEST(E2ERights, HostileSetValuesFailTheSubmitWithAReasonAndValidOnesReachTheConverter) {
  OpenDaemon d;
  d.start();
  const std::string pic = atelier::test::test_image("pic1.png").string();
  const std::string deep = "width=" + std::string(30000, '[') + std::string(30000, ']');
  json r = d.daemon.request("submit", {{"path", pic}, {"kind", "knit"}, {"set", {deep}}});
  EXPECT_FALSE(r.value("ok", true));
  EXPECT_NE(r.value("error", "").find("width"), std::string::npos) << r.dump().substr(0, 400);
  EXPECT_LT(r.value("error", "").size(), 5000u) << "the reason echoes the whole value";
  EXPECT_TRUE(d.daemon.request("status").value("ok", false));
  // A value too long to be one argument of the converter is refused before it is tried.
  const std::string huge = "width=" + std::string(200000, '[');
  r = d.daemon.request("submit", {{"path", pic}, {"kind", "knit"}, {"set", {huge}}});
  EXPECT_NE(r.value("error", "").find("--set width: 200006 bytes is longer than the limit of 65536 bytes"),
            std::string::npos)
      << r.dump().substr(0, 400);
  EXPECT_TRUE(d.daemon.jobs().empty());

  r = d.daemon.request("submit", {{"path", pic}, {"kind", "knit"}, {"set", {"width=30", "dither=atkinson"}}});
  ASSERT_TRUE(r.value("ok", false)) << r;
  ASSERT_TRUE(d.daemon.wait_job_state("pic1.png", "completed")) << d.daemon.jobs();
  const fs::path out = d.daemon.job_named("pic1.png")["output_dir"].get<std::string>();
  EXPECT_EQ(cv::imread((out / "pattern.png").string(), cv::IMREAD_GRAYSCALE).cols, 30);
  EXPECT_EQ(d.daemon.stop(SIGTERM), 0);
}

}  // namespace
