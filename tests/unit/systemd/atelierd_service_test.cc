// The systemd integration files, checked by systemd's own tools.
//
// This container has no systemd as PID 1. `systemd-analyze verify` still works offline: it
// loads the unit file (and the stock units it references from /lib/systemd/system), checks
// every directive, and checks that ExecStart's binary exists and is executable. It exits 0
// even for unknown keys, printing a warning that names the file, so the tests assert that no
// stderr line names atelierd. --man=no: the unit lists no man pages to look up.
// --generators=no: generators need privileges and only add unrelated units.
// `systemd-sysusers --root=DIR` and `systemd-tmpfiles --root=DIR --create` apply the
// sysusers.d/tmpfiles.d files to a scratch root (names resolve against DIR/etc/passwd).
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace {

namespace fs = std::filesystem;

const fs::path kSource = ATELIER_SOURCE_DIR "/systemd";
const fs::path kBuild = ATELIER_BINARY_DIR;
// The unit as configured for this build tree: ExecStart is <build>/bin/atelierd.
const fs::path kBuildTreeUnit = kBuild / "systemd/build-tree/atelierd.service";
// The unit as installed: ExecStart is <prefix>/bin/atelierd.
const fs::path kInstallUnit = kBuild / "systemd/atelierd.service";

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Result {
  int exit_code;
  std::string out;
  std::string err;
};

class SystemdUnitTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/atelier-systemd-test-XXXXXX";
    ASSERT_NE(::mkdtemp(pattern), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { fs::remove_all(dir_); }

  Result sh(const std::string& command) {
    fs::path out = dir_ / ".stdout", err = dir_ / ".stderr";
    std::string full = "( " + command + " ) >'" + out.string() + "' 2>'" + err.string() + "'";
    int status = std::system(full.c_str());
    Result r{WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), read_file(out),
             read_file(err)};
    fs::remove(out);
    fs::remove(err);
    return r;
  }

  Result verify(const fs::path& unit) {
    return sh("SYSTEMD_LOG_COLOR=0 systemd-analyze verify --man=no --generators=no '" +
              unit.string() + "'");
  }

  fs::path dir_;
};

// Lines of systemd-analyze's stderr that are about our unit (it may also warn about other
// units installed in the container).
std::vector<std::string> lines_naming_atelierd(const std::string& text) {
  std::vector<std::string> hits;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.find("atelierd") != std::string::npos) hits.push_back(line);
  }
  return hits;
}

// [Service] Key=Value pairs; a repeated key keeps its last value, as systemd would for these.
std::map<std::string, std::string> service_settings(const std::string& unit) {
  std::map<std::string, std::string> settings;
  std::istringstream in(unit);
  std::string section;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    if (line[0] == '[') {
      section = line;
      continue;
    }
    auto eq = line.find('=');
    if (section == "[Service]" && eq != std::string::npos) {
      settings[line.substr(0, eq)] = line.substr(eq + 1);
    }
  }
  return settings;
}

// Every value of a [Service] key that may repeat (DeviceAllow=, SystemCallFilter=).
std::vector<std::string> service_values(const std::string& unit, const std::string& key) {
  std::vector<std::string> values;
  std::istringstream in(unit);
  std::string section;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] == '[') section = line;
    if (section == "[Service]" && line.rfind(key + "=", 0) == 0) values.push_back(line.substr(key.size() + 1));
  }
  return values;
}

TEST_F(SystemdUnitTest, BuildTreeUnitPassesSystemdAnalyzeVerify) {
  ASSERT_TRUE(fs::exists(kBuildTreeUnit)) << kBuildTreeUnit << " not configured";
  ASSERT_TRUE(fs::exists(kBuild / "bin/atelierd"))
      << "build atelierd first: the unit is verified with the real ExecStart";
  // systemd-analyze wants the unit under its own name; verify a copy in the scratch dir so
  // stray files beside it (none today) cannot matter.
  fs::copy_file(kBuildTreeUnit, dir_ / "atelierd.service");
  Result r = verify(dir_ / "atelierd.service");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(lines_naming_atelierd(r.err), std::vector<std::string>{}) << r.err;
}

TEST_F(SystemdUnitTest, VerifyCheckCatchesMistakes) {
  // The assertions above can fail: a misspelt key and a missing binary are reported.
  std::string unit = read_file(kBuildTreeUnit);
  ASSERT_FALSE(unit.empty());
  std::string typo = unit;
  typo.replace(typo.find("WatchdogSec="), 12, "WatchDogSec=");
  std::ofstream(dir_ / "atelierd.service") << typo;
  Result r = verify(dir_ / "atelierd.service");
  EXPECT_NE(lines_naming_atelierd(r.err), std::vector<std::string>{}) << r.err;

  std::string missing = unit;
  auto exec = missing.find("ExecStart=") + 10;
  missing.insert(exec, "/nonexistent");
  std::ofstream(dir_ / "atelierd.service", std::ios::trunc) << missing;
  r = verify(dir_ / "atelierd.service");
  EXPECT_NE(r.exit_code, 0) << r.err;
}

TEST_F(SystemdUnitTest, InstalledUnitDiffersOnlyInExecStartPath) {
  std::string installed = read_file(kInstallUnit);
  std::string build_tree = read_file(kBuildTreeUnit);
  ASSERT_FALSE(installed.empty()) << kInstallUnit;
  auto installed_exec = service_settings(installed)["ExecStart"];
  auto build_exec = service_settings(build_tree)["ExecStart"];
  std::string installed_binary = installed_exec.substr(0, installed_exec.find(' '));
  std::string build_binary = build_exec.substr(0, build_exec.find(' '));
  EXPECT_EQ(build_binary, (kBuild / "bin/atelierd").string());
  EXPECT_EQ(fs::path(installed_binary).filename(), "atelierd");
  EXPECT_TRUE(fs::path(installed_binary).is_absolute()) << installed_binary;
  // So what systemd-analyze verified above is exactly what gets installed.
  build_tree.replace(build_tree.find(build_binary), build_binary.size(), installed_binary);
  EXPECT_EQ(installed, build_tree);
}

TEST_F(SystemdUnitTest, UnitRunsSandboxedButKeepsSerialPorts) {
  auto s = service_settings(read_file(kInstallUnit));
  EXPECT_EQ(s["Type"], "notify");
  EXPECT_EQ(s["NotifyAccess"], "main");
  // The config the install put in place (<sysconfdir>/atelier; /etc/atelier for prefix /usr).
  EXPECT_TRUE(s["ExecStart"].ends_with("etc/atelier/atelierd.toml")) << s["ExecStart"];
  EXPECT_NE(s["ExecStart"].find(" --config /"), std::string::npos) << s["ExecStart"];
  EXPECT_EQ(s["ExecReload"], "/bin/kill -HUP $MAINPID");
  EXPECT_EQ(s["WatchdogSec"], "30");
  EXPECT_EQ(s["Restart"], "on-failure");
  EXPECT_EQ(s["User"], "atelier");
  EXPECT_EQ(s["Group"], "atelier");
  EXPECT_EQ(s["SupplementaryGroups"], "dialout");
  EXPECT_EQ(s["StateDirectory"], "atelier");
  EXPECT_EQ(s["RuntimeDirectory"], "atelier");
  EXPECT_EQ(s["RuntimeDirectoryMode"], "0750");
  EXPECT_EQ(s["ProtectSystem"], "strict");
  // The spool, and where file-drop devices' sticks and shares are mounted.
  EXPECT_EQ(s["ReadWritePaths"], "/var/spool/atelier -/media -/mnt -/run/media");
  EXPECT_EQ(s["NoNewPrivileges"], "yes");
  // Outputs and the store group-readable only, as atelierd's own umask.
  EXPECT_EQ(s["UMask"], "0027");
  EXPECT_EQ(s["RestrictAddressFamilies"], "AF_UNIX AF_NETLINK");
  // PrivateDevices= would hide /dev/ttyACM* and /dev/ttyUSB*: the machines. The device ACL
  // keeps them, USB devices for libusb, and the emulators' pseudo-terminals.
  EXPECT_EQ(s.count("PrivateDevices"), 0u);
  EXPECT_EQ(s["DevicePolicy"], "closed");
  const std::string unit = read_file(kInstallUnit);
  EXPECT_EQ(service_values(unit, "DeviceAllow"),
            (std::vector<std::string>{"char-ttyACM rw", "char-ttyUSB rw", "char-usb_device rw",
                                      "char-pts rw"}));
  // `atelierctl submit` passes open files, so home folders can be hidden entirely.
  EXPECT_EQ(s["ProtectHome"], "yes");
  EXPECT_EQ(s["CapabilityBoundingSet"], "");
  EXPECT_EQ(service_values(unit, "SystemCallFilter"),
            (std::vector<std::string>{"@system-service", "~@privileged @resources", "@chown setrlimit"}));
  EXPECT_EQ(s["SystemCallErrorNumber"], "EPERM");
}

TEST_F(SystemdUnitTest, SecurityExposureIsAtMostTwoAndAHalf) {
  // `systemd-analyze security` rates the sandbox from 0 (locked down) to 10; the unit had 7.1
  // (MEDIUM) before it set a capability bounding set, a system-call filter and the rest.
  fs::copy_file(kBuildTreeUnit, dir_ / "atelierd.service");
  Result r = sh("SYSTEMD_LOG_COLOR=0 SYSTEMD_COLORS=0 systemd-analyze security --offline=true "
                "--no-pager '" + (dir_ / "atelierd.service").string() + "'");
  const std::string marker = "Overall exposure level for atelierd.service: ";
  const auto at = r.out.find(marker);
  ASSERT_NE(at, std::string::npos) << r.out << r.err;
  const double exposure = std::stod(r.out.substr(at + marker.size()));
  std::cout << "systemd-analyze security: exposure " << exposure << "\n";
  EXPECT_LE(exposure, 2.5) << r.out;
}

TEST_F(SystemdUnitTest, InstallWithPrefixUsrGivesTheDebianLayout) {
  // `cmake --install build --prefix /usr` (and the package, which CPack installs with prefix
  // /usr) from this build, whatever prefix it was configured with: the config in /etc/atelier,
  // where the unit's --config looks, the unit and udev rules in /lib (Debian bookworm),
  // sysusers.d and tmpfiles.d in /usr/lib, and ExecStart the installed daemon.
  fs::path stage = dir_ / "stage";
  Result r = sh("DESTDIR='" + stage.string() + "' cmake --install '" + kBuild.string() +
                "' --prefix /usr --component atelier");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_TRUE(fs::exists(stage / "etc/atelier/atelierd.toml"));
  EXPECT_FALSE(fs::exists(stage / "usr/etc"));
  EXPECT_TRUE(fs::exists(stage / "lib/udev/rules.d/60-atelier.rules"));
  EXPECT_TRUE(fs::exists(stage / "usr/lib/sysusers.d/atelier.conf"));
  EXPECT_TRUE(fs::exists(stage / "usr/lib/tmpfiles.d/atelier.conf"));
  EXPECT_TRUE(fs::exists(stage / "usr/bin/atelierd"));
  auto s = service_settings(read_file(stage / "lib/systemd/system/atelierd.service"));
  EXPECT_EQ(s["ExecStart"], "/usr/bin/atelierd --config /etc/atelier/atelierd.toml");
}

TEST_F(SystemdUnitTest, InstalledUnitNamesTheFilesOfTheInstallTimePrefix) {
  // Another prefix at install time than at configure time: the unit still starts the daemon
  // this install put in place, with the config this install put in place.
  fs::path stage = dir_ / "stage", prefix = dir_ / "elsewhere";
  Result r = sh("DESTDIR='" + stage.string() + "' cmake --install '" + kBuild.string() +
                "' --prefix '" + prefix.string() + "' --component atelier");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const fs::path unit = stage / prefix.relative_path() / "lib/systemd/system/atelierd.service";
  ASSERT_TRUE(fs::exists(unit)) << unit;
  const std::string exec = service_settings(read_file(unit))["ExecStart"];
  EXPECT_EQ(exec, (prefix / "bin/atelierd").string() + " --config " +
                      (prefix / "etc/atelier/atelierd.toml").string());
  EXPECT_TRUE(fs::exists(stage / prefix.relative_path() / "bin/atelierd"));
  EXPECT_TRUE(fs::exists(stage / prefix.relative_path() / "etc/atelier/atelierd.toml"));
}

TEST_F(SystemdUnitTest, SysusersCreatesAtelierUserInDialout) {
  fs::create_directories(dir_ / "root/etc");
  Result r = sh("systemd-sysusers --root='" + (dir_ / "root").string() + "' '" +
                (kSource / "atelier.sysusers").string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::string passwd = read_file(dir_ / "root/etc/passwd");
  std::string group = read_file(dir_ / "root/etc/group");
  // atelier:x:UID:GID:GECOS:/var/lib/atelier:/usr/sbin/nologin, a system (low) uid.
  std::istringstream users(passwd);
  std::string user_line;
  for (std::string line; std::getline(users, line);) {
    if (line.rfind("atelier:", 0) == 0) user_line = line;
  }
  ASSERT_FALSE(user_line.empty()) << passwd;
  EXPECT_NE(user_line.find(":/var/lib/atelier:"), std::string::npos) << user_line;
  EXPECT_NE(user_line.find("nologin"), std::string::npos) << user_line;
  EXPECT_TRUE(group.rfind("atelier:x:", 0) == 0 || group.find("\natelier:x:") != std::string::npos)
      << group;
  std::istringstream groups(group);
  bool in_dialout = false;
  for (std::string line; std::getline(groups, line);) {
    if (line.rfind("dialout:", 0) == 0) in_dialout = line.substr(line.rfind(':') + 1) == "atelier";
  }
  EXPECT_TRUE(in_dialout) << group;
}

TEST_F(SystemdUnitTest, TmpfilesCreatesSpoolWithDropFolderPermissions) {
  fs::path root = dir_ / "root";
  fs::create_directories(root / "etc");
  Result r = sh("systemd-sysusers --root='" + root.string() + "' '" +
                (kSource / "atelier.sysusers").string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = sh("systemd-tmpfiles --root='" + root.string() + "' --create '" +
         (kSource / "atelier.tmpfiles").string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;

  // uid and gid of atelier in the scratch root (not the host's).
  unsigned uid = 0, gid = 0;
  {
    std::istringstream in(read_file(root / "etc/passwd"));
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("atelier:", 0) == 0) std::sscanf(line.c_str(), "atelier:x:%u:%u:", &uid, &gid);
    }
  }
  ASSERT_NE(uid, 0u);

  const std::map<std::string, mode_t> expected = {
      {"var/spool/atelier", 0750},          {"var/spool/atelier/incoming", 02775},
      {"var/spool/atelier/incoming/knit", 02775}, {"var/spool/atelier/done", 0750},
      {"var/spool/atelier/failed", 0750},   {"var/spool/atelier/work", 0750}};
  for (const auto& [path, mode] : expected) {
    struct stat st {};
    ASSERT_EQ(::stat((root / path).c_str(), &st), 0) << path << " not created";
    EXPECT_TRUE(S_ISDIR(st.st_mode)) << path;
    EXPECT_EQ(st.st_mode & 07777, mode) << path << std::oct << " has mode " << (st.st_mode & 07777);
    EXPECT_EQ(st.st_uid, uid) << path;
    EXPECT_EQ(st.st_gid, gid) << path;
  }
}

TEST_F(SystemdUnitTest, InstallPutsFilesWhereSystemdLooks) {
  // DESTDIR install of the whole build: the unit, sysusers.d and tmpfiles.d entries land in
  // <prefix>/lib/..., and the installed unit's ExecStart is the installed daemon.
  Result r = sh("DESTDIR='" + (dir_ / "stage").string() + "' cmake --install '" +
                kBuild.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  fs::path unit, sysusers, tmpfiles;
  for (const auto& entry : fs::recursive_directory_iterator(dir_ / "stage")) {
    std::string p = entry.path().string();
    if (p.ends_with("/lib/systemd/system/atelierd.service")) unit = entry.path();
    if (p.ends_with("/lib/sysusers.d/atelier.conf")) sysusers = entry.path();
    if (p.ends_with("/lib/tmpfiles.d/atelier.conf")) tmpfiles = entry.path();
  }
  ASSERT_FALSE(unit.empty()) << "no lib/systemd/system/atelierd.service installed";
  EXPECT_FALSE(sysusers.empty()) << "no lib/sysusers.d/atelier.conf installed";
  EXPECT_FALSE(tmpfiles.empty()) << "no lib/tmpfiles.d/atelier.conf installed";
  EXPECT_EQ(read_file(sysusers), read_file(kSource / "atelier.sysusers"));
  EXPECT_EQ(read_file(tmpfiles), read_file(kSource / "atelier.tmpfiles"));
  std::string exec = service_settings(read_file(unit))["ExecStart"];
  fs::path daemon = dir_ / "stage" / fs::path(exec.substr(0, exec.find(' '))).relative_path();
  EXPECT_TRUE(fs::exists(daemon)) << "the unit starts " << exec.substr(0, exec.find(' '))
                                  << " but the install put no atelierd there";
  EXPECT_EQ(::access(daemon.c_str(), X_OK), 0) << daemon;
}

}  // namespace

TEST_F(SystemdUnitTest, GeneratorOpensTheSandboxOnlyForTheWebPage) {
  // The installed generator runs the installed daemon on the installed config: nothing while
  // [web] is off; with it on, a drop-in allowing AF_INET from localhost, which systemd accepts
  // on top of the unit.
  const fs::path prefix = dir_ / "prefix";
  Result r = sh("cmake --install '" + kBuild.string() + "' --prefix '" + prefix.string() + "' --component atelier");
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const fs::path generator = prefix / "lib/systemd/system-generators/atelierd-generator";
  ASSERT_TRUE(fs::exists(generator));
  const fs::path out = dir_ / "generated";
  fs::create_directories(out);
  r = sh("'" + generator.string() + "' '" + out.string() + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(fs::exists(out / "atelierd.service.d/50-web.conf")) << "a drop-in with [web] off";

  // The packaged config has [web] with its keys commented out: turn it on there.
  r = sh("sed -i 's/^# enabled = false /enabled = true /' '" + (prefix / "etc/atelier/atelierd.toml").string() + "'");
  ASSERT_EQ(r.exit_code, 0);
  r = sh("'" + generator.string() + "' '" + out.string() + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const std::string dropin = read_file(out / "atelierd.service.d/50-web.conf");
  EXPECT_EQ(service_values(dropin, "RestrictAddressFamilies"),
            (std::vector<std::string>{"", "AF_UNIX AF_NETLINK AF_INET"})) << dropin;
  EXPECT_EQ(service_values(dropin, "IPAddressAllow"), std::vector<std::string>{"localhost"}) << dropin;

  // The unit with the drop-in beside it, as systemd loads them.
  fs::copy_file(prefix / "lib/systemd/system/atelierd.service", out / "atelierd.service");
  r = sh("SYSTEMD_LOG_COLOR=0 SYSTEMD_UNIT_PATH='" + out.string() +
         ":' systemd-analyze verify --man=no --generators=no '" + (out / "atelierd.service").string() + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(lines_naming_atelierd(r.err), std::vector<std::string>{}) << r.err;

  // A config that does not load: no drop-in, the unit's own sandbox stays.
  fs::remove(out / "atelierd.service.d/50-web.conf");
  std::ofstream(prefix / "etc/atelier/atelierd.toml", std::ios::app) << "\nbogus = 1\n";
  r = sh("'" + generator.string() + "' '" + out.string() + "'");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_FALSE(fs::exists(out / "atelierd.service.d/50-web.conf"));
}
