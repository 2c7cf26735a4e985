#include "daemon/scan_check.h"

#include <string>

#include "base/error.h"

namespace fs = std::filesystem;

namespace atelier {

void check_scans_decode(const fs::path& exe, const std::vector<fs::path>& files, const ChildLimits& limits) {
  if (files.empty()) return;
  std::vector<std::string> argv = {exe.string(), "--decode-check"};
  for (const auto& f : files) argv.push_back(f.string());
  const ChildResult child = run_child(argv, limits);
  if (child.ok()) return;
  std::string names;
  for (const auto& f : files) names += (names.empty() ? "" : ", ") + f.filename().string();
  if (child.end == ChildResult::End::timed_out || child.out_of_cpu())
    throw BadInput(names + ": decoding took longer than the limit for a scan; is it an image?");
  if (child.end == ChildResult::End::signaled)
    throw BadInput(names + ": the image decoder stopped with signal " + std::to_string(child.code) +
                   " (out of memory, or a file that crashes it); nothing was added");
  std::string message = first_line(child.err);
  if (message.rfind("error: ", 0) == 0) message.erase(0, 7);
  if (message.empty()) message = names + ": cannot be decoded as an image";
  throw BadInput(message);
}

}  // namespace atelier
