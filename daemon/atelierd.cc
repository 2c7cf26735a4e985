// atelierd: the workshop fabrication daemon. See README.md and DESIGN.md.
#include <sys/stat.h>

#include <CLI/CLI.hpp>
#include <iostream>
#include <string>

#include "base/cli_parse.h"
#include "convert/common/param_table.h"
#include "daemon/config.h"
#include "daemon/daemon.h"
#include "daemon/log.h"
#include "daemon/web/password.h"
#include "daemon/web/sandbox_dropin.h"

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
  bool hash_password = false;
  bool sandbox_dropin = false;
  app.add_flag("--hash-password", hash_password,
               "read a password from standard input and print its hash for [web.users], then exit");
  app.add_flag("--sandbox-dropin", sandbox_dropin,
               "print the systemd drop-in that lets the unit listen as [web] says (the generator runs this), "
               "then exit");
  app.set_version_flag("--version", "atelierd " ATELIER_VERSION, "print \"atelierd VERSION\" and exit");
  if (auto stop = atelier::parse_command_line(app, argc, argv)) return *stop;
  if (hash_password) {
    std::string password;
    std::getline(std::cin, password);
    if (password.empty()) {
      std::cerr << "atelierd --hash-password: no password on standard input\n";
      return 2;
    }
    try {
      std::cout << atelier::web::hash_password(password) << "\n";
    } catch (const std::exception& e) {
      std::cerr << "atelierd --hash-password: " << e.what() << "\n";
      return 1;
    }
    return 0;
  }
  atelier::log::set_verbose(verbose);
  atelier::log::init();  // native journal entries under systemd, plain stderr lines otherwise
  atelier::Config config;
  try {
    config = atelier::load_config(config_file);
  } catch (const std::exception& e) {
    atelier::log::error(std::string("configuration error: ") + e.what());
    return 1;
  }
  if (sandbox_dropin) {
    std::cout << atelier::web::sandbox_dropin(config.web, config_file);
    return 0;
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
