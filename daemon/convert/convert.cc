#include "daemon/convert/convert.h"

#include <algorithm>

#include "daemon/convert/cut_job.h"
#include "daemon/convert/embroidery_job.h"
#include "daemon/convert/embroidery_params.h"
#include "daemon/convert/knit_job.h"
#include "daemon/convert/knit_params.h"
#include "daemon/convert/lace_job.h"
#include "daemon/convert/lace_params.h"
#include "daemon/convert/param_table.h"
#include "daemon/convert/parquetry_job.h"
#include "daemon/convert/parquetry_params.h"
#include "daemon/convert/sketch_job.h"
#include "daemon/convert/sketch_params.h"

namespace atelier {
namespace {

std::string kind_list() {
  std::string list;
  for (const auto& k : known_kinds()) list += (list.empty() ? "" : ", ") + k;
  return list;
}

}  // namespace

const std::vector<std::string>& known_kinds() {
  static const std::vector<std::string> kinds{"knit", "cut", "parquetry", "embroidery", "lace", "sketch"};
  return kinds;
}

bool converts_job_file(const std::string& kind) { return kind == "lace"; }

bool is_known_kind(const std::string& kind) {
  const auto& kinds = known_kinds();
  return std::find(kinds.begin(), kinds.end(), kind) != kinds.end();
}

void validate_kind_params(const std::string& kind, const toml::table& params,
                          const std::string& source) {
  if (kind == "knit") {
    read_knit_params(params, source);
    return;
  }
  if (kind == "cut") {
    read_cut_params(params, source);
    return;
  }
  if (kind == "parquetry") {
    read_parquetry_params(params, source);
    return;
  }
  if (kind == "embroidery") {
    read_embroidery_params(params, source);
    return;
  }
  if (kind == "lace") {
    read_lace_params(params, source);
    return;
  }
  if (kind == "sketch") {
    read_sketch_params(params, source);
    return;
  }
  throw ParamError(source + ": unknown kind '" + kind + "' (known: " + kind_list() + ")");
}

ConvertResult convert(const ConvertRequest& request) {
  if (!is_known_kind(request.kind)) {
    throw ConvertError(request.input.filename().string() + ": unknown kind '" + request.kind +
                       "' (known: " + kind_list() + ")");
  }
  if (!request.together.empty() && request.kind != "parquetry") {
    throw ConvertError(request.input.filename().string() + ": only parquetry converts several "
                       "targets together, not " + request.kind);
  }
  // OpenCV reports bad data (and its own limits) by exception; the user sees the file name.
  try {
    if (request.kind == "cut") return convert_cut(request);
    if (request.kind == "parquetry") return convert_parquetry(request);
    if (request.kind == "embroidery") return convert_embroidery(request);
    if (request.kind == "lace") return convert_lace(request);
    if (request.kind == "sketch") return convert_sketch(request);
    return convert_knit(request);
  } catch (const cv::Exception& e) {
    throw ConvertError(request.input.filename().string() + ": image processing failed: " +
                       e.err);
  } catch (const std::invalid_argument& e) {
    throw ConvertError(request.input.filename().string() + ": " + e.what());
  }
}

}  // namespace atelier
