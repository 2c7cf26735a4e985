#include "convert/job_file_kind.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <toml++/toml.h>

#include "convert/kinds.h"

namespace atelier {
namespace {

// A value from the file is echoed only when it looks like a mistyped kind name: short, and
// nothing but lower-case letters, digits, '-' and '_'.
bool echoable(const std::string& value) {
  if (value.empty() || value.size() > 32) return false;
  for (char c : value)
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_')) return false;
  return true;
}

}  // namespace

std::string description_without_content(const std::string& description) {
  std::string d = description;
  // "..., saw 'x'" names the input's character: drop the clause.
  if (size_t saw = d.find(", saw "); saw != std::string::npos) d.erase(saw);
  // Quoted text: grammar tokens of one punctuation character stay ('='), anything else is
  // the input's (a key name, a value) and goes.
  std::string out;
  for (size_t i = 0; i < d.size(); ++i) {
    if (d[i] != '\'') {
      out += d[i];
      continue;
    }
    size_t end = d.find('\'', i + 1);
    if (end == std::string::npos) break;  // an unbalanced quote: stop before it
    const std::string inner = d.substr(i + 1, end - i - 1);
    const bool token = inner.size() == 1 && std::ispunct(static_cast<unsigned char>(inner[0]));
    out += token ? "'" + inner + "'" : "'...'";
    i = end;
  }
  while (!out.empty() && (out.back() == ' ' || out.back() == ':' || out.back() == ',')) out.pop_back();
  return out;
}

JobFileKind read_job_file_kind(const std::filesystem::path& file, const std::string& shown_name) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return {"", shown_name + ": cannot open: " + std::strerror(errno)};
  std::ostringstream text;
  text << in.rdbuf();
  toml::table table;
  try {
    table = toml::parse(text.str(), std::string_view{shown_name});
  } catch (const toml::parse_error& e) {
    return {"", shown_name + ":" + std::to_string(e.source().begin.line) + ":" +
                    std::to_string(e.source().begin.column) + ": not a TOML job file (" +
                    description_without_content(std::string(e.description())) + ")"};
  }
  auto kind = table["kind"].value<std::string>();
  if (!kind) return {"", shown_name + ": a job file needs kind = \"...\" (kinds: " + known_kinds_text() + ")"};
  if (!is_known_kind(*kind))
    return {"", shown_name + ": unknown kind" + (echoable(*kind) ? " '" + *kind + "'" : "") +
                    " (kinds: " + known_kinds_text() + ")"};
  if (!converts_job_file(*kind))
    return {"", shown_name + ": kind '" + *kind + "' converts an image: drop the image into incoming/" +
                    *kind + "/ (with an optional sidecar NAME.EXT.toml)"};
  return {*kind, ""};
}

}  // namespace atelier
