#include "daemon/spool_layout.h"

#include "convert/kinds.h"

namespace atelier {
namespace {
bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}
}  // namespace

bool is_temporary_name(const std::string& name) {
  if (name.empty() || name[0] == '.') return true;
  for (const char* suffix : {"~", ".part", ".tmp", ".crdownload", ".swp"})
    if (ends_with(name, suffix)) return true;
  return false;
}

std::optional<std::string> companion_of(const std::string& name) {
  for (const std::string& suffix : companion_suffixes()) {
    if (ends_with(name, suffix) && name.size() > suffix.size()) {
      std::string image = name.substr(0, name.size() - suffix.size());
      // "job.toml" at the top level is a job file, not a sidecar: a sidecar's image has an
      // extension of its own.
      if (image.find('.') != std::string::npos) return image;
    }
  }
  return std::nullopt;
}

}  // namespace atelier
