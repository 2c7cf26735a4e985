// Pencil profiles as files: the TOML format users keep their own pencils in, the profiles that
// ship with atelier (2H .. 8B, compiled in from data/pencils/*.toml), and the `pencil`
// parameter of sketch and line jobs (a shipped grade or a profile file).
//
// The format ("atelier-pencil-profile 1"), one TOML table:
//   format = "atelier-pencil-profile 1"   name = "6B"   source = "where it was learned from"
//   width_px = 7.1                         (mean run length across the line, px)
//   min_mid, max_mid, min_range, max_range (grey levels 0..255, see algorithms/pencil/profile.h)
//   mid_pixels, line_pixels                (how many centre / line pixels were counted)
//   mid_hist, hist = [256 whole counts]    (per grey level; they sum to mid_pixels / line_pixels)
//   ccm = [[i, j, count], ...]             (the non-zero cells of the 256 x 256 co-occurrence
//                                           matrix: i = upper pixel, j = the one below)
// Counts rather than normalised doubles, so that reading gives back exactly the doubles that
// learn_profile computed. Reading is strict: an unknown key, a wrong type, a value out of range
// or totals that do not add up is a ConvertError "FILE:LINE: key 'ccm': ...".
//
// Thread-safe: no shared mutable state (the shipped profiles are parsed once, on first use).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "algorithms/pencil/profile.h"
#include "convert/common/job_paths.h"

namespace atelier {

inline constexpr std::string_view kPencilProfileFormat = "atelier-pencil-profile 1";

// The profile as a commented TOML text; `source` (e.g. the scan's file name) goes into the
// header and the `source` key. Throws std::invalid_argument for a profile without pixel counts
// (mid_pixels, line_pixels, ccm_pairs: learn_profile fills them) or without 256-bin histograms
// and a 256 x 256 ccm.
std::string profile_to_toml(const pencil::PencilProfile& profile, const std::string& source = "");

// Parses and checks a profile; `source` names the text in errors (the file's path). Throws
// ConvertError "SOURCE:LINE: key 'K': problem" (or "SOURCE:LINE: " + the TOML syntax error).
pencil::PencilProfile profile_from_toml(std::string_view text, const std::string& source);

// Reads a profile file (at most 4 MiB: twice the largest profile_to_toml writes). Throws
// ConvertError naming the file.
pencil::PencilProfile load_profile_file(const std::filesystem::path& file);
// The same, opened through `access` (job_paths.h: confined when a job named the file).
pencil::PencilProfile load_profile_file(const PathAccess& access, const std::filesystem::path& file);

// The grades that ship with atelier, light to dark: {"2H", "H", "F", "HB", "B", "3B", "6B", "8B"}
// (the embedded data/pencils/*.toml files, in the order of pencil::grade_models()).
const std::vector<std::string>& shipped_pencils();

// A shipped profile by grade name, case-insensitive ("6b" is "6B"). Throws std::invalid_argument
// listing the shipped grades for an unknown name.
pencil::PencilProfile shipped_pencil(const std::string& name);

// The `pencil` parameter of sketch and line jobs: a shipped grade name (case-insensitive), or
// the path of a .toml profile (relative paths are relative to `base_dir`; "" = the current
// folder). Throws ConvertError "SOURCE: key 'pencil': ..." naming the value (and the file's
// own error for a bad profile file; the shipped grades for an unknown name).
pencil::PencilProfile resolve_pencil(const std::string& value, const std::filesystem::path& base_dir,
                                     const std::string& source);
// The same with the file opened through `access` (relative paths from its base).
pencil::PencilProfile open_pencil(const std::string& value, const PathAccess& access,
                                     const std::string& source);

namespace detail {
// The embedded data/pencils/*.toml files as {file stem, text}: defined in the shipped_pencils.cc
// that convert/sketch/shipped_pencils.cmake generates at configure time.
const std::vector<std::pair<std::string_view, std::string_view>>& embedded_pencil_files();
}  // namespace detail

}  // namespace atelier
