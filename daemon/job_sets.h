// A job's `--set` overrides as the store keeps them (Job::params), without parsing TOML in the
// daemon: the "key=value" strings go to the converter child as they were given (it parses
// them, where a crash costs one job).
//
//   new jobs:   a JSON array of the strings, e.g. ["max_float=5","dither=atkinson"]; "" for none
//   old stores: the TOML text earlier versions wrote ("key = value" lines, maybe [table]
//               sections), turned back into "key=value" strings line by line, textually
//
// Pure functions; thread-safe.
#pragma once

#include <string>
#include <vector>

namespace atelier {

// The stored form of `sets` ("" when empty).
std::string sets_to_params(const std::vector<std::string>& sets);

// The "key=value" strings of a stored Job::params, new or old form (see above). Lines of old
// text that are no assignment are skipped.
std::vector<std::string> params_to_sets(const std::string& params);

}  // namespace atelier
