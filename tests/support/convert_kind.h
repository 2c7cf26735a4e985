// Runs convert() for one kind as atelierd's child does for a job with a sidecar: the
// parameters parsed from `params_toml` as the file "test.toml" and validated strictly first
// (so an unknown key throws ParamError naming test.toml), the outputs into `output_dir`.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "convert/common/param_table.h"
#include "convert/convert.h"
#include "convert/kinds.h"

namespace atelier::test {

inline ConvertResult convert_kind(const std::string& kind, const std::filesystem::path& input,
                                  const std::string& params_toml, const std::filesystem::path& output_dir) {
  ConvertRequest req;
  req.kind = kind;
  req.input = input;
  req.params = toml::parse(params_toml, std::string_view{"test.toml"});
  validate_kind_params(kind, req.params, "test.toml");
  req.output_dir = output_dir;
  return convert(req);
}

}  // namespace atelier::test
