#include "daemon/log.h"

#include <unistd.h>

#include <atomic>

namespace atelier::log {
namespace {
std::atomic<bool> g_verbose{false};

void emit(const char* prefix, const std::string& msg) {
  std::string line = std::string(prefix) + msg + "\n";
  // One write so lines from different threads never interleave.
  ssize_t ignored = ::write(STDERR_FILENO, line.data(), line.size());
  (void)ignored;
}
}  // namespace

void error(const std::string& msg) { emit("<3>", msg); }
void warning(const std::string& msg) { emit("<4>", msg); }
void info(const std::string& msg) { emit("<6>", msg); }
void debug(const std::string& msg) {
  if (g_verbose) emit("<7>", msg);
}
void set_verbose(bool on) { g_verbose = on; }

}  // namespace atelier::log
