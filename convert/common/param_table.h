// Strict reading of TOML tables: every key must be known and of the right type.
//
// Used for the daemon config, per-kind parameter sections, sidecars and `--set` overrides.
// Errors name the file, the line and the key (`ParamError::what()` is ready for a user),
// because a silently ignored typo in a config is worse than a refusal to start.
// Not thread-safe per instance; values returned are copies.
#pragma once

#include <toml++/toml.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/error.h"

namespace atelier {

class ParamError : public BadInput {
 public:
  using BadInput::BadInput;
};

// "FILE:LINE: " for a node parsed from a file, "FILE: " when no line is known.
std::string where(const toml::node& node, const std::string& fallback_source);

// "SOURCE:LINE:COLUMN: not valid TOML: PROBLEM" for a syntax error, never quoting the text
// that was read (toml++'s descriptions say "saw 'x'" or quote keys and values; those parts
// are dropped or replaced by '...').
std::string toml_error_text(const toml::parse_error& error, const std::string& source);

// Replaces a relative path string at t[key] by base / path (lexically normal); an absolute
// or empty value, or a key that is absent or not a string, is left as it is.
void make_path_absolute(toml::table& t, const std::string& key, const std::filesystem::path& base);

// Which keys the TableReaders look up, for the test that holds config/atelierd.toml and its
// man page to the code (tests/unit/config/atelierd_toml_test.cc). While a ParamKeyLog lives,
// every TableReader on the same thread adds each key it reads or asks about (has()), with the
// table it asked and the default its get_*() was given. Costs a thread-local test otherwise.
struct ParamKeyUse {
  const toml::table* table = nullptr;  // the table asked; not owned, valid while the caller's is
  std::string key;
  // The default the get_*() call was given (TOML value under "v"); empty for has(), get_table()
  // and get_array(), which have none.
  toml::table default_value;
};
class ParamKeyLog {
 public:
  ParamKeyLog();   // the thread's log until destroyed (one at a time per thread)
  ~ParamKeyLog();
  ParamKeyLog(const ParamKeyLog&) = delete;
  ParamKeyLog& operator=(const ParamKeyLog&) = delete;
  const std::vector<ParamKeyUse>& uses() const { return uses_; }
  void add(ParamKeyUse use) { uses_.push_back(std::move(use)); }

 private:
  ParamKeyLog* previous_;
  std::vector<ParamKeyUse> uses_;
};

// Reads keys out of one table and remembers which were read, so that `finish()` can
// reject every key that nobody asked for. `source` names the file (or "--set") for errors
// when a node carries no source information of its own.
class TableReader {
 public:
  TableReader(const toml::table& table, std::string source, std::string section);

  // Each returns the value if present, the default otherwise; throws ParamError on a
  // wrong type or a value outside [lo, hi].
  bool get_bool(const std::string& key, bool def);
  int64_t get_int(const std::string& key, int64_t def, int64_t lo, int64_t hi);
  double get_double(const std::string& key, double def, double lo, double hi);  // ints accepted
  std::string get_string(const std::string& key, const std::string& def);
  // A string that must be one of `choices`.
  std::string get_choice(const std::string& key, const std::string& def,
                         const std::vector<std::string>& choices);
  std::vector<std::string> get_string_list(const std::string& key,
                                           const std::vector<std::string>& def);
  // A nested table (e.g. `[[device]]` entries are read by the caller); nullptr if absent.
  const toml::table* get_table(const std::string& key);
  const toml::array* get_array(const std::string& key);
  bool has(const std::string& key) const;

  // Throws ParamError naming the first key that was never read.
  void finish() const;

  [[noreturn]] void fail(const std::string& key, const std::string& problem) const;

 private:
  const toml::node* node(const std::string& key);
  // Tells the thread's ParamKeyLog (if any) the default `key` was read with.
  template <typename T>
  void note_default(const std::string& key, const T& def) const;
  const toml::table& table_;
  std::string source_;
  std::string section_;
  std::set<std::string> read_;
};

// The folder that relative paths in `node` are relative to: its file's folder when it came
// from a file, else "" (the cwd). "--set" and "parameters" are not files.
std::filesystem::path param_base_dir(const toml::node& node);
// `path` as given in `node`, made relative to param_base_dir(node) unless absolute.
std::filesystem::path resolve_param_path(const std::filesystem::path& path, const toml::node& node);

// Parses `key=value` as given to `--set`: the value is TOML (number, bool, quoted string,
// array); anything that is not valid TOML is taken as a bare string. Dotted keys are not
// supported. Throws ParamError on a missing '='.
void apply_set(toml::table& target, const std::string& assignment);

// Copies every key of `overrides` into `base`, replacing existing values. Tables are merged
// key by key (a sidecar's `[laser]` with only `s_max` keeps the configured layers); arrays,
// such as `[[laser.layer]]`, are replaced whole.
void merge_into(toml::table& base, const toml::table& overrides);

}  // namespace atelier
