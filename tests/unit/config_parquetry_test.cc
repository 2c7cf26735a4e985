// The daemon's parquetry wood: by default the library and the stock of used wood live in the
// state folder (the store's folder); a config's own `wood` and `stock` win, relative to the
// config file, since the conversion reads them from its standard input.
#include <gtest/gtest.h>

#include "daemon/config.h"

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
