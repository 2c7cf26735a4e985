// Logging to stderr with systemd priority prefixes ("<3>" error ... "<7>" debug), which
// journald turns into priorities. Thread-safe: each message is written with one write(2).
#pragma once

#include <string>

namespace atelier::log {

void error(const std::string& msg);
void warning(const std::string& msg);
void info(const std::string& msg);
void debug(const std::string& msg);
// Debug messages are dropped unless enabled (atelierd --verbose).
void set_verbose(bool on);

}  // namespace atelier::log
