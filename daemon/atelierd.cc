// atelierd: the workshop fabrication daemon. See README.md and DESIGN.md.
#include <sys/stat.h>

#include <CLI/CLI.hpp>
#include <iostream>

#include "base/cli_parse.h"
#include "convert/common/param_table.h"
#include "daemon/config.h"
#include "daemon/daemon.h"
#include "daemon/log.h"

int main(int argc, char** argv) {
  // Outputs, spool folders and the store are for the daemon and its group only: files 0640,
  // folders 0750 (the systemd unit's UMask= says the same).
  ::umask(0027);
  CLI::App app{"atelierd: turns images dropped into a hot folder into fabrication data"};
  std::string config_file = "/etc/atelier/atelierd.toml";
  bool verbose = false;
  bool check = false;
  app.add_option("-c,--config", config_file, "configuration file")->capture_default_str();
  app.add_flag("-v,--verbose", verbose, "log debug messages");
  app.add_flag("--check-config", check, "validate the configuration and exit");
  app.set_version_flag("--version", "atelierd " ATELIER_VERSION, "print \"atelierd VERSION\" and exit");
  if (auto stop = atelier::parse_command_line(app, argc, argv)) return *stop;
  atelier::log::set_verbose(verbose);
  atelier::log::init();  // native journal entries under systemd, plain stderr lines otherwise
  atelier::Config config;
  try {
    config = atelier::load_config(config_file);
  } catch (const std::exception& e) {
    atelier::log::error(std::string("configuration error: ") + e.what());
    return 1;
  }
  if (check) {
    std::cout << config_file << ": ok\n";
    return 0;
  }
  try {
    atelier::Daemon daemon(config_file, std::move(config));
    return daemon.run();
  } catch (const std::exception& e) {
    atelier::log::error(std::string("cannot start: ") + e.what());
    return 1;
  }
}
