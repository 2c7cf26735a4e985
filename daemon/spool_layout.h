// The spool folder's layout (DESIGN.md "Hot folder") and the naming rules for what is
// dropped into it. Pure functions and paths; no state.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace atelier {

struct SpoolLayout {
  std::filesystem::path root;
  std::filesystem::path incoming() const { return root / "incoming"; }
  std::filesystem::path incoming(const std::string& kind) const { return incoming() / kind; }
  std::filesystem::path work() const { return root / "work"; }      // claimed, not finished
  std::filesystem::path done() const { return root / "done"; }
  std::filesystem::path failed() const { return root / "failed"; }
  std::filesystem::path work(int64_t id) const { return work() / std::to_string(id); }
  std::filesystem::path done(int64_t id) const { return done() / std::to_string(id); }
  std::filesystem::path failed(int64_t id) const { return failed() / std::to_string(id); }
};

// Names still being written (leading dot, trailing '~', ".part", ".tmp", ".crdownload"):
// ignored until renamed.
bool is_temporary_name(const std::string& name);

// Files that travel with an image rather than being jobs themselves: its sidecar
// "NAME.EXT.toml" and its relax mask "NAME.EXT.relax.png". Returns the image's name.
std::optional<std::string> companion_of(const std::string& name);

}  // namespace atelier
