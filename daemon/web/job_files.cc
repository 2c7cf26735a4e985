#include "daemon/web/job_files.h"

#include <fcntl.h>
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <map>

#include "convert/kinds.h"

namespace fs = std::filesystem;

namespace atelier::web {
namespace {

bool all_digits(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); });
}

UniqueFd open_below(int dir, const std::string& name, int flags) {
  return UniqueFd(::openat(dir, name.c_str(), flags | O_NOFOLLOW | O_CLOEXEC));
}

std::string extension(const std::string& name) {
  const auto dot = name.rfind('.');
  if (dot == std::string::npos) return "";
  std::string ext = name.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

}  // namespace

std::optional<OpenedFile> open_job_file(const fs::path& spool_dir, const fs::path& output_dir,
                                        const std::string& name) {
  if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos ||
      name.find('\0') != std::string::npos)
    return std::nullopt;
  const fs::path relative = output_dir.lexically_normal().lexically_relative(spool_dir.lexically_normal());
  std::vector<std::string> parts;
  for (const auto& p : relative) parts.push_back(p.string());
  if (parts.size() != 2 || (parts[0] != "done" && parts[0] != "failed") || !all_digits(parts[1]))
    return std::nullopt;
  // The spool itself is the administrator's (it may be a symlink to a bigger disk).
  UniqueFd spool(::open(spool_dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (!spool.valid()) return std::nullopt;
  UniqueFd folder = open_below(spool.get(), parts[0], O_RDONLY | O_DIRECTORY);
  if (!folder.valid()) return std::nullopt;
  UniqueFd job = open_below(folder.get(), parts[1], O_RDONLY | O_DIRECTORY);
  if (!job.valid()) return std::nullopt;
  // O_NONBLOCK: a FIFO planted there must not hang the server thread in open().
  UniqueFd file = open_below(job.get(), name, O_RDONLY | O_NONBLOCK);
  if (!file.valid()) return std::nullopt;
  struct stat st{};
  if (::fstat(file.get(), &st) != 0 || !S_ISREG(st.st_mode)) return std::nullopt;
  const int flags = ::fcntl(file.get(), F_GETFL);
  if (flags >= 0) ::fcntl(file.get(), F_SETFL, flags & ~O_NONBLOCK);
  return OpenedFile{std::move(file), static_cast<uint64_t>(st.st_size)};
}

std::string content_type_for(const std::string& name) {
  static const std::map<std::string, std::string> types = {
      {"png", "image/png"},           {"jpg", "image/jpeg"},
      {"jpeg", "image/jpeg"},         {"gif", "image/gif"},
      {"webp", "image/webp"},         {"bmp", "image/bmp"},
      {"svg", "image/svg+xml"},       {"pdf", "application/pdf"},
      {"json", "application/json"},   {"txt", "text/plain; charset=utf-8"},
      {"k", "text/plain; charset=utf-8"}, {"gcode", "text/plain; charset=utf-8"},
      {"toml", "text/plain; charset=utf-8"}, {"csv", "text/csv; charset=utf-8"}};
  auto it = types.find(extension(name));
  return it == types.end() ? "application/octet-stream" : it->second;
}

bool shown_inline(const std::string& name) {
  const std::string type = content_type_for(name);
  return type.rfind("image/", 0) == 0 || type.rfind("text/", 0) == 0 || type == "application/json";
}

std::vector<std::string> preview_files(const std::string& kind, const std::vector<std::string>& outputs) {
  std::vector<std::string> out;
  const KindInfo* k = find_kind(kind);
  if (!k) return out;
  for (std::string_view p : k->previews)
    if (std::find(outputs.begin(), outputs.end(), p) != outputs.end()) out.emplace_back(p);
  return out;
}

}  // namespace atelier::web
