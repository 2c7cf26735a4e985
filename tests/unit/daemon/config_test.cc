// The daemon config (daemon/config.h) is strict: typos and wrong types stop the daemon with
// file, line, key. And the parquetry wood it hands the conversions.
#include <gtest/gtest.h>

#include "convert/common/param_table.h"
#include "daemon/config.h"

using atelier::Config;
using atelier::ParamError;
using atelier::parse_config;

namespace {
std::string error_of(const std::string& text) {
  try {
    parse_config(text, "/etc/atelier/atelierd.toml");
  } catch (const ParamError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Config, AllowPathsAreResolvedAgainstTheConfigAndJoinTheSpoolAsConfinement) {
  Config c = parse_config("[spool]\ndir = \"/srv/spool\"\nallow_paths = [\"/srv/scans\", \"shared\"]\n",
                          "/etc/atelier/atelierd.toml");
  EXPECT_EQ(c.confine_dirs(),
            (std::vector<std::filesystem::path>{"/srv/spool", "/srv/scans", "/etc/atelier/shared"}));
  EXPECT_EQ(parse_config("[spool]\ndir = \"/srv/spool\"\n", "x.toml").confine_dirs(),
            std::vector<std::filesystem::path>{"/srv/spool"});
  EXPECT_THROW(parse_config("[spool]\ndir = \"/s\"\nallow_paths = \"/srv\"\n", "x.toml"), atelier::ParamError);
}

TEST(Config, ThreeLinesAreEnoughAndEverythingElseHasDefaults) {
  Config c = parse_config(
      "[spool]\ndir = \"/srv/spool\"\n[store]\npath = \"/srv/jobs.sqlite\"\n"
      "[control]\nsocket = \"/srv/ctl.sock\"\n",
      "/etc/atelier/atelierd.toml");
  EXPECT_EQ(c.spool_dir, "/srv/spool");
  EXPECT_EQ(c.store_path, "/srv/jobs.sqlite");
  EXPECT_EQ(c.socket_path, "/srv/ctl.sock");
  EXPECT_EQ(c.watch, atelier::WatchMode::inotify);
  EXPECT_EQ(c.settle_ms, 500);
  EXPECT_EQ(c.workers, 2);
  EXPECT_EQ(c.job_timeout_s, 600);
  EXPECT_EQ(c.limits.max_pixels, 40000000u);
  EXPECT_EQ(c.limits.max_file_bytes, 209715200u);
  EXPECT_EQ(c.job_memory_mb, 2048);
  EXPECT_TRUE(c.devices.empty());
  EXPECT_TRUE(c.kind_defaults.count("knit"));
}

TEST(Config, JobMemoryBudgetIsALimitsKeyWithABound) {
  EXPECT_EQ(parse_config("[spool]\ndir = \"/s\"\n[limits]\njob_memory_mb = 700\n", "a.toml").job_memory_mb, 700);
  std::string e = error_of("[spool]\ndir = \"/s\"\n[limits]\njob_memory_mb = 10\n");
  EXPECT_NE(e.find("limits.job_memory_mb"), std::string::npos) << e;
}

TEST(Config, RetentionKeepsThirtyDaysAndFiveHundredJobsUnlessTheStoreSectionSaysOtherwise) {
  Config c = parse_config("[spool]\ndir = \"/s\"\n", "a.toml");
  EXPECT_EQ(c.keep_days, 30);
  EXPECT_EQ(c.keep_jobs, 500);
  c = parse_config("[spool]\ndir = \"/s\"\n[store]\nkeep_days = 0\nkeep_jobs = 20\n", "a.toml");
  EXPECT_EQ(c.keep_days, 0);
  EXPECT_EQ(c.keep_jobs, 20);
  std::string e = error_of("[spool]\ndir = \"/s\"\n[store]\nkeep_days = -1\n");
  EXPECT_NE(e.find("atelierd.toml:4: key 'store.keep_days': value -1 is outside [0, 36500]"), std::string::npos) << e;
  e = error_of("[spool]\ndir = \"/s\"\n[store]\nkeep_jobs = \"all\"\n");
  EXPECT_NE(e.find("key 'store.keep_jobs': expected an integer"), std::string::npos) << e;
}

TEST(Config, RelativePathsFollowTheConfigFile) {
  Config c = parse_config("[spool]\ndir = \"spool\"\n", "/opt/demo/atelierd.toml");
  EXPECT_EQ(c.spool_dir, "/opt/demo/spool");
  // Also a drop folder and embroidery textures (conversions read their parameters from stdin).
  c = parse_config("[spool]\ndir = \"/s\"\n[embroidery]\ntextures = \"tex\"\n[[device]]\nname = \"emb\"\n"
                   "driver = \"file-drop\"\ndir = \"usb\"\n", "/opt/demo/atelierd.toml");
  EXPECT_EQ(c.devices[0].dir, "/opt/demo/usb");
  EXPECT_EQ(c.kind_defaults["embroidery"]["textures"].value_or(std::string()), "/opt/demo/tex");
}

TEST(Config, MissingSpoolDirIsAnError) {
  EXPECT_NE(error_of("[store]\npath = \"x\"\n").find("[spool]"), std::string::npos);
  EXPECT_NE(error_of("[spool]\nwatch = \"poll\"\n").find("spool.dir"), std::string::npos);
}

TEST(Config, UnknownKeyNamesFileLineAndKey) {
  std::string e = error_of("[spool]\ndir = \"/s\"\n\n[limits]\nworkerz = 3\n");
  EXPECT_NE(e.find("/etc/atelier/atelierd.toml:5"), std::string::npos) << e;
  EXPECT_NE(e.find("limits.workerz"), std::string::npos) << e;
}

TEST(Config, UnknownSectionIsAnError) {
  std::string e = error_of("[spool]\ndir = \"/s\"\n[spooll]\ndir = \"/t\"\n");
  EXPECT_NE(e.find("spooll"), std::string::npos) << e;
}

TEST(Config, WrongTypeNamesTheKey) {
  std::string e = error_of("[spool]\ndir = \"/s\"\n[limits]\nworkers = \"two\"\n");
  EXPECT_NE(e.find(":4"), std::string::npos) << e;
  EXPECT_NE(e.find("limits.workers"), std::string::npos) << e;
  EXPECT_NE(e.find("integer"), std::string::npos) << e;
}

TEST(Config, BadChoiceListsTheChoices) {
  std::string e = error_of("[spool]\ndir = \"/s\"\nwatch = \"fanotify\"\n");
  EXPECT_NE(e.find("inotify, poll"), std::string::npos) << e;
}

TEST(Config, KnitSectionIsCheckedToo) {
  std::string e = error_of("[spool]\ndir = \"/s\"\n[knit]\nmax_flaot = 3\n");
  EXPECT_NE(e.find(":4"), std::string::npos) << e;
  EXPECT_NE(e.find("max_flaot"), std::string::npos) << e;
  e = error_of("[spool]\ndir = \"/s\"\n[knit]\nsolver = \"simulated-annealing\"\n");
  EXPECT_NE(e.find("solver"), std::string::npos) << e;
}

TEST(Config, KnitDefaultsAreKeptForJobs) {
  Config c = parse_config("[spool]\ndir = \"/s\"\n[knit]\nwidth = 150\n", "a.toml");
  EXPECT_EQ(c.kind_defaults.at("knit")["width"].value<int64_t>(), 150);
}

TEST(Config, SyntaxErrorNamesTheLine) {
  std::string e = error_of("[spool]\ndir = \"/s\"\n[limits\n");
  EXPECT_NE(e.find("atelierd.toml:3"), std::string::npos) << e;
}

TEST(Config, AFileDropDeviceDeliversEmbroideryInDstAndExpWithoutBeingStarted) {
  const atelier::Config c = atelier::parse_config(
      "[spool]\ndir = \"/s\"\n[[device]]\nname = \"emb\"\ndriver = \"file-drop\"\n"
      "dir = \"/media/EMB\"\n", "atelierd.toml");
  ASSERT_EQ(c.devices.size(), 1u);
  EXPECT_EQ(c.devices[0].dir, "/media/EMB");
  EXPECT_EQ(c.devices[0].formats, (std::vector<std::string>{"dst", "exp"}));
  EXPECT_EQ(c.devices[0].kinds, (std::vector<std::string>{"embroidery"}));
  EXPECT_TRUE(c.devices[0].autostart);
}

TEST(Config, AFileDropDeviceForAHomeMachineDeliversPesAndJef) {
  const atelier::Config c = atelier::parse_config(
      "[spool]\ndir = \"/s\"\n[[device]]\nname = \"brother\"\ndriver = \"file-drop\"\n"
      "dir = \"/media/EMB\"\nformats = [\"pes\", \"jef\"]\n", "atelierd.toml");
  ASSERT_EQ(c.devices.size(), 1u);
  EXPECT_EQ(c.devices[0].formats, (std::vector<std::string>{"pes", "jef"}));
}

TEST(Config, AFileDropDeviceWithoutAFolderOrWithAnUnknownFormatIsRefused) {
  std::string e = error_of("[spool]\ndir = \"/s\"\n[[device]]\nname = \"emb\"\ndriver = \"file-drop\"\n");
  EXPECT_NE(e.find("emb"), std::string::npos) << e;
  EXPECT_NE(e.find("dir"), std::string::npos) << e;
  e = error_of("[spool]\ndir = \"/s\"\n[[device]]\nname = \"emb\"\ndriver = \"file-drop\"\n"
               "dir = \"/m\"\nformats = [\"dst\", \"vp3\"]\n");
  EXPECT_NE(e.find("'vp3'"), std::string::npos) << e;
  EXPECT_NE(e.find("\"pes\", \"jef\""), std::string::npos) << e;  // the known ones are listed
  e = error_of("[spool]\ndir = \"/s\"\n[[device]]\nname = \"emb\"\ndriver = \"file-drop\"\n"
               "dir = \"/m\"\nkinds = [\"knit\"]\n");
  EXPECT_NE(e.find("embroidery jobs only"), std::string::npos) << e;
  e = error_of("[spool]\ndir = \"/s\"\n[[device]]\nname = \"x\"\ndriver = \"ayab\"\nprot = \"/dev/x\"\n");
  EXPECT_NE(e.find("prot"), std::string::npos) << e;
}

TEST(Config, ALaserWaitsForTheOperatorAndTakesOnlyLaserKinds) {
  Config c = parse_config(
      "[spool]\ndir = \"/s\"\n[[device]]\nname = \"laser\"\ndriver = \"grbl\"\n"
      "port = \"/dev/ttyUSB0\"\n", "a.toml");
  ASSERT_EQ(c.devices.size(), 1u);
  EXPECT_FALSE(c.devices[0].autostart);
  // Every laser kind this build converts.
  EXPECT_EQ(c.devices[0].kinds, (std::vector<std::string>{"cut", "parquetry", "sketch", "engrave"}));
  EXPECT_EQ(c.devices[0].streaming, "character-counting");
  EXPECT_FALSE(c.laser_check_first);

  std::string e = error_of(
      "[spool]\ndir = \"/s\"\n[[device]]\nname = \"laser\"\ndriver = \"grbl\"\n"
      "port = \"/dev/ttyUSB0\"\nkinds = [\"knit\"]\n");
  EXPECT_NE(e.find(":7:"), std::string::npos) << e;
  EXPECT_NE(e.find("cannot run 'knit'"), std::string::npos) << e;
  e = error_of("[spool]\ndir = \"/s\"\n[[device]]\nname = \"laser\"\ndriver = \"grbl\"\n");
  EXPECT_NE(e.find("needs port"), std::string::npos) << e;
  e = error_of("[spool]\ndir = \"/s\"\n[[device]]\nname = \"laser\"\ndriver = \"grbl\"\n"
               "port = \"/dev/ttyUSB0\"\nstreaming = \"fast\"\n");
  EXPECT_NE(e.find("streaming"), std::string::npos) << e;
}

TEST(Config, ASketchPencilFileIsRelativeToTheConfigAndAGradeIsChecked) {
  Config c = parse_config("[spool]\ndir = \"/s\"\n[sketch]\npencil = \"pencils/mine.toml\"\n", "/etc/atelier/a.toml");
  EXPECT_EQ(c.kind_defaults["sketch"]["pencil"].value_or(std::string{}), "/etc/atelier/pencils/mine.toml");
  c = parse_config("[spool]\ndir = \"/s\"\n[sketch]\npencil = \"6b\"\n", "/etc/atelier/a.toml");
  EXPECT_EQ(c.kind_defaults["sketch"]["pencil"].value_or(std::string{}), "6b");  // a grade, not a file
  const std::string e = error_of("[spool]\ndir = \"/s\"\n[sketch]\npencil = \"9B\"\n");
  EXPECT_NE(e.find(":4: key 'pencil'"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown pencil '9B'"), std::string::npos) << e;
}

TEST(Config, TheLaserSectionIsCheckedAndHandedToTheLaserKinds) {
  Config c = parse_config(
      "[spool]\ndir = \"/s\"\n[laser]\ncheck_first = true\ns_max = 255\n"
      "[[laser.layer]]\ncolor = \"#ff0000\"\nmode = \"cut\"\nspeed_mm_min = 400\n", "a.toml");
  EXPECT_TRUE(c.laser_check_first);
  const toml::table* laser = c.kind_defaults.at("cut")["laser"].as_table();
  ASSERT_NE(laser, nullptr);
  EXPECT_EQ((*laser)["s_max"].value<int64_t>(), 255);
  EXPECT_FALSE(c.kind_defaults.at("knit").contains("laser"));

  std::string e = error_of("[spool]\ndir = \"/s\"\n[laser]\n[[laser.layer]]\ncolor = \"#ff0000\"\nspeed = 400\n");
  EXPECT_NE(e.find(":6:"), std::string::npos) << e;
  EXPECT_NE(e.find("speed"), std::string::npos) << e;
}

TEST(Config, AKnittingMachineHasDefaultsAndIsChecked) {
  Config c = parse_config(
      "[spool]\ndir = \"/s\"\n[[device]]\nname = \"knitter\"\ndriver = \"ayab\"\n"
      "port = \"/dev/ttyACM0\"\n", "a.toml");
  ASSERT_EQ(c.devices.size(), 1u);
  const auto& d = c.devices[0];
  EXPECT_EQ(d.machine, "kh930");
  EXPECT_EQ(d.kinds, std::vector<std::string>{"knit"});
  EXPECT_FALSE(d.autostart);  // one piece at a time: the knitter starts each job
  EXPECT_EQ(d.mode, "single-bed");
  EXPECT_EQ(d.start_needle, -1);
  std::string e = error_of("[spool]\ndir = \"/s\"\n[[device]]\nname = \"k\"\ndriver = \"ayab\"\n");
  EXPECT_NE(e.find("port"), std::string::npos) << e;
  e = error_of("[spool]\ndir = \"/s\"\n[[device]]\nname = \"k\"\ndriver = \"ayab\"\n"
               "port = \"/dev/x\"\nmachine = \"kh999\"\n");
  EXPECT_NE(e.find("kh930"), std::string::npos) << e;
}

// The row order is the job's ([knit] first_row): chart.pdf and pattern.k are drawn for it, so a
// device may not knit another order. The old [[device]] key is refused, naming the new place.
TEST(Config, ADevicesFirstRowIsRefusedNamingTheKnitSection) {
  const std::string e = error_of("[spool]\ndir = \"/s\"\n[[device]]\nname = \"k\"\ndriver = \"ayab\"\n"
                                 "port = \"/dev/x\"\nfirst_row = \"top\"\n");
  EXPECT_NE(e.find(":7"), std::string::npos) << e;
  EXPECT_NE(e.find("first_row"), std::string::npos) << e;
  EXPECT_NE(e.find("[knit]"), std::string::npos) << e;
  EXPECT_NE(e.find("sidecar"), std::string::npos) << e;
}

TEST(Config, SetOverridesParseTomlValuesAndBareWords) {
  toml::table t;
  atelier::apply_set(t, "width=90");
  atelier::apply_set(t, "dither=atkinson");
  atelier::apply_set(t, "anchoring=false");
  atelier::apply_set(t, "colors=[\"#ffffff\", \"#000000\"]");
  EXPECT_EQ(t["width"].value<int64_t>(), 90);
  EXPECT_EQ(t["dither"].value<std::string>(), "atkinson");
  EXPECT_EQ(t["anchoring"].value<bool>(), false);
  EXPECT_TRUE(t["colors"].is_array());
  EXPECT_THROW(atelier::apply_set(t, "novalue"), ParamError);
}

TEST(Config, AJobsOverridesMergeIntoTablesKeyByKey) {
  // A sidecar that only changes the power scale keeps the configured layers.
  toml::table base = toml::parse("[laser]\ns_max = 1000\ntravel_mm_min = 5000\n"
                                 "[[laser.layer]]\ncolor = \"#ff0000\"\n");
  toml::table sidecar = toml::parse("[laser]\ns_max = 255\n");
  atelier::merge_into(base, sidecar);
  EXPECT_EQ(base["laser"]["s_max"].value<int64_t>(), 255);
  EXPECT_EQ(base["laser"]["travel_mm_min"].value<int64_t>(), 5000);
  ASSERT_NE(base["laser"]["layer"].as_array(), nullptr);
  // An array is replaced whole: a job's own layer list is the whole list.
  toml::table layers = toml::parse("[[laser.layer]]\ncolor = \"#000000\"\n[[laser.layer]]\ncolor = \"#0000ff\"\n");
  atelier::merge_into(base, layers);
  EXPECT_EQ(base["laser"]["layer"].as_array()->size(), 2u);
  EXPECT_EQ(base["laser"]["layer"][0]["color"].value<std::string>(), "#000000");
}

TEST(Config, AKnittingMachineKnitsKnitAndLaceJobsOnly) {
  Config c = parse_config("[spool]\ndir = \"/s\"\n[lace]\nstart_chart = \"charts/diamond.json\"\n"
                          "[[device]]\nname = \"k\"\ndriver = \"ayab\"\nport = \"/dev/x\"\n"
                          "kinds = [\"knit\", \"lace\"]\n",
                          "/etc/atelier/atelierd.toml");
  ASSERT_EQ(c.devices.size(), 1u);
  EXPECT_EQ(c.devices[0].kinds, (std::vector<std::string>{"knit", "lace"}));
  // The converter reads its parameters from a pipe: a relative start chart follows the config.
  EXPECT_EQ(c.kind_defaults.at("lace")["start_chart"].value<std::string>(),
            std::optional<std::string>("/etc/atelier/charts/diamond.json"));
  const std::string e = error_of("[spool]\ndir = \"/s\"\n[[device]]\nname = \"k\"\ndriver = \"ayab\"\n"
                                 "port = \"/dev/x\"\nkinds = [\"knit\", \"cut\"]\n");
  EXPECT_NE(e.find("knits 'knit' and 'lace' jobs, not 'cut'"), std::string::npos) << e;
  EXPECT_NE(error_of("[spool]\ndir = \"/s\"\n[lace]\nwidht = 3\n").find("widht"), std::string::npos);
}

// The daemon's parquetry wood: by default the library and the stock of used wood live in the
// state folder (the store's folder); a config's own `wood` and `stock` win, relative to the
// config file, since the conversion reads them from its standard input.
namespace atelier {
namespace {

std::string str(const toml::table& t, const char* key) { return t[key].value_or(std::string()); }

TEST(ConfigParquetry, WoodAndStockDefaultToTheStateFolder) {
  Config c = parse_config("[spool]\ndir = \"/s\"\n[store]\npath = \"/var/lib/atelier/jobs.sqlite\"\n",
                          "/etc/atelier/atelierd.toml");
  EXPECT_EQ(c.state_dir(), "/var/lib/atelier");
  const toml::table& p = c.kind_defaults.at("parquetry");
  EXPECT_EQ(str(p, "wood"), "/var/lib/atelier/wood");
  EXPECT_EQ(str(p, "stock"), "/var/lib/atelier/wood-stock");
}

TEST(ConfigParquetry, TheConfigsOwnWoodAndStockWinAndAreMadeAbsolute) {
  Config c = parse_config(
      "[spool]\ndir = \"/s\"\n[parquetry]\nwood = \"veneers\"\nstock = \"/srv/stock\"\ndpi = 600\n",
      "/etc/atelier/atelierd.toml");
  const toml::table& p = c.kind_defaults.at("parquetry");
  EXPECT_EQ(str(p, "wood"), "/etc/atelier/veneers");
  EXPECT_EQ(str(p, "stock"), "/srv/stock");
  EXPECT_EQ(p["dpi"].value_or(0.0), 600.0);
}

TEST(ConfigParquetry, AListOfSheetsGetsAbsoluteImagePaths) {
  Config c = parse_config(
      "[spool]\ndir = \"/s\"\n[parquetry]\nwood = [{id = \"oak\", image = \"scans/oak.png\", "
      "mask = \"/m/oak.png\"}]\n",
      "/etc/atelier/atelierd.toml");
  const toml::table& p = c.kind_defaults.at("parquetry");
  const toml::table* sheet = p["wood"].as_array()->get(0)->as_table();
  EXPECT_EQ(str(*sheet, "image"), "/etc/atelier/scans/oak.png");
  EXPECT_EQ(str(*sheet, "mask"), "/m/oak.png");
}

}  // namespace
}  // namespace atelier

TEST(Config, WebIsOffByDefaultOnLoopback) {
  Config c = parse_config("[spool]\ndir = \"/s\"\n", "x.toml");
  EXPECT_FALSE(c.web.enabled);
  EXPECT_EQ(c.web.host, "127.0.0.1");
  EXPECT_EQ(c.web.port, 8631);
  EXPECT_EQ(c.web.allow_from, std::vector<std::string>{"localhost"});
  EXPECT_FALSE(c.web.can_act());
}

TEST(Config, WebReadsListenTokenAndUsers) {
  Config c = parse_config(
      "[spool]\ndir = \"/s\"\n[web]\nenabled = true\nlisten = \"0.0.0.0:9000\"\n"
      "token = \"0123456789abcdef\"\nsession_hours = 2\n[web.users]\nalice = \"$y$j9T$abc$def\"\n",
      "x.toml");
  EXPECT_TRUE(c.web.enabled);
  EXPECT_EQ(c.web.host, "0.0.0.0");
  EXPECT_EQ(c.web.port, 9000);
  EXPECT_EQ(c.web.allow_from, std::vector<std::string>{"any"});  // a LAN address: the LAN
  EXPECT_EQ(c.web.session_hours, 2);
  EXPECT_EQ(c.web.users.at("alice"), "$y$j9T$abc$def");
  EXPECT_TRUE(c.web.can_act());
}

TEST(Config, WebRefusesBadValuesNamingTheKey) {
  EXPECT_NE(error_of("[spool]\ndir = \"/s\"\n[web]\nlisten = \"8631\"\n").find("web.listen"), std::string::npos);
  EXPECT_NE(error_of("[spool]\ndir = \"/s\"\n[web]\nallow_from = [\"lan\"]\n").find("web.allow_from"),
            std::string::npos);
  EXPECT_NE(error_of("[spool]\ndir = \"/s\"\n[web]\ntoken = \"short\"\n").find("at least 16"), std::string::npos);
  EXPECT_NE(error_of("[spool]\ndir = \"/s\"\n[web.users]\nbob = \"hunter2\"\n").find("web.users.bob"),
            std::string::npos);
  EXPECT_NE(error_of("[spool]\ndir = \"/s\"\n[web]\nenable = true\n").find("enable"), std::string::npos);
  EXPECT_NE(error_of("[spool]\ndir = \"/s\"\n[web]\nserver_names = [\"http://box:80\"]\n").find("web.server_names"),
            std::string::npos);
}
