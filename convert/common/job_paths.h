// What the converter may read on a job's behalf.
//
// atelierd runs atelier-convert with its own rights (root or user `atelier`), so a path that
// a job names (a value in a sidecar NAME.EXT.toml, a job file incoming/NAME.toml or `--set`)
// must not reach files the job's author could not read. With confinement on
// (`atelier-convert --confine DIR`, repeatable: the spool and `[spool] allow_paths`), such a
// path must lie inside one of those folders, and it is opened race-free: openat2(2) from a
// descriptor of the folder with RESOLVE_BENEATH | RESOLVE_NO_SYMLINKS, so neither `..` nor a
// symlink anywhere on the way (the last component included) can lead out, and the bytes are
// read from that descriptor. Paths from the daemon's own config (`--params`) are trusted and
// opened as given, as is everything when no folder is given (a user running atelier-convert
// by hand on their own files).
//
// Every failure is a ConvertError "SOURCE: key 'KEY': PATH: PROBLEM" (SOURCE: the sidecar, job
// file or "--set" the value came from; PATH shown with display_name()).
// Ownership: values; PathAccess copies what it needs. Threading: const methods are safe from
// any thread; the file descriptors returned are the caller's.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "base/unique_fd.h"

namespace atelier {

// How the files named by one parameter are opened: confined beneath `roots` (when `roots` is
// not empty) or as given. A default-constructed PathAccess is unconfined with no key.
class PathAccess {
 public:
  PathAccess() = default;
  // `roots`: absolute folders, or empty for no confinement. `key`, `source`: for messages.
  // `base`: the folder a relative path is taken from (empty: the working directory).
  PathAccess(std::vector<std::filesystem::path> roots, std::string key, std::string source,
             std::filesystem::path base);

  bool confined() const { return !roots_.empty(); }
  // The same access with other names for messages (e.g. none, when the caller prefixes its own).
  PathAccess relabeled(std::string key, std::string source) const {
    return PathAccess(roots_, std::move(key), std::move(source), base_);
  }
  const std::string& key() const { return key_; }
  const std::string& source() const { return source_; }
  // A parameter's value taken against the base when relative (lexically normal). The methods
  // below take paths as they are (absolute, or relative to the working directory): a caller
  // with a value as the job gave it resolves it first.
  std::filesystem::path resolve(const std::filesystem::path& path) const;

  // Opens a regular file for reading (O_RDONLY, O_CLOEXEC; a FIFO or device is refused
  // without blocking). Throws ConvertError.
  UniqueFd open_file(const std::filesystem::path& path) const;
  // Opens a folder (O_DIRECTORY). Throws ConvertError.
  UniqueFd open_dir(const std::filesystem::path& path) const;
  // The whole file, at most `max_bytes` (a larger file is refused with both sizes). An empty
  // file is returned empty. Throws ConvertError.
  std::vector<unsigned char> read_file(const std::filesystem::path& path, uint64_t max_bytes) const;
  std::string read_text(const std::filesystem::path& path, uint64_t max_bytes) const;
  // The names of the regular files in a folder, sorted ("." and ".." and anything else left
  // out; confined, a symlink is left out too, unconfined it counts as what it points to).
  // Throws ConvertError.
  std::vector<std::string> list_files(const std::filesystem::path& dir) const;
  // Whether `path` names a regular file this access may open (false for a refused path).
  bool is_file(const std::filesystem::path& path) const;
  bool is_dir(const std::filesystem::path& path) const;

  // "SOURCE: key 'KEY': PATH: " (or "PATH: " with no key), for a caller's own messages.
  std::string prefix(const std::filesystem::path& path) const;
  [[noreturn]] void fail(const std::filesystem::path& path, const std::string& problem) const;

 private:
  // Opens with `flags` (O_DIRECTORY or not); errno-style failures become ConvertError.
  UniqueFd open(const std::filesystem::path& path, int flags) const;
  std::vector<std::filesystem::path> roots_;
  std::string key_, source_;
  std::filesystem::path base_;
};

// The confinement of one conversion and where each job-set parameter came from.
class JobPaths {
 public:
  JobPaths() = default;  // unconfined
  // `roots`: the spool and [spool] allow_paths (made absolute); empty = unconfined.
  explicit JobPaths(std::vector<std::filesystem::path> roots);

  bool confined() const { return !roots_.empty(); }
  const std::vector<std::filesystem::path>& roots() const { return roots_; }
  // Records that `key`'s final value came from a job layer `source` (a sidecar or job file
  // path, or "--set"), whose relative paths are taken from `base`.
  void mark_from_job(const std::string& key, const std::string& source, const std::filesystem::path& base);
  bool from_job(const std::string& key) const { return job_keys_.count(key) != 0; }
  // The source named for `key` ("" when not from a job).
  std::string source_of(const std::string& key) const;
  // How to open what `key` names: confined when it came from a job and roots are set;
  // otherwise as given, relative paths from `default_base`.
  PathAccess access(const std::string& key, const std::filesystem::path& default_base = {}) const;
  // For job content that is not a parameter (a companion such as NAME.EXT.relax.png): always
  // confined when roots are set. `what` names it in messages.
  PathAccess companion(const std::string& what) const;

 private:
  struct Origin {
    std::string source;
    std::filesystem::path base;
  };
  std::vector<std::filesystem::path> roots_;
  std::map<std::string, Origin> job_keys_;
};

}  // namespace atelier
