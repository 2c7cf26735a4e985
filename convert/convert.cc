#include "convert/convert.h"

#include "convert/common/display_text.h"

#include <algorithm>
#include <opencv2/core.hpp>
#include <stdexcept>

#include "convert/common/output_files.h"
#include "convert/kinds.h"
#include "convert/report_file.h"

namespace atelier {

void report_progress(const ConvertRequest& req, double fraction) {
  if (req.progress) req.progress(std::clamp(fraction, 0.0, 1.0));
}

ConvertResult finish_report(const ConvertRequest& req, const std::filesystem::path& out,
                            const nlohmann::ordered_json& report, ConvertResult result) {
  write_output(out / report_file_name(), report.dump(2) + "\n");
  report_progress(req, 1.0);
  result.report = nlohmann::json::parse(report.dump());
  return result;
}

ConvertResult convert(const ConvertRequest& request) {
  const KindInfo* kind = find_kind(request.kind);
  if (!kind) {
    throw ConvertError(display_name(request.input) + ": unknown kind '" + display_value(request.kind) +
                       "' (known: " + known_kinds_text() + ")");
  }
  if (!request.together.empty() && !kind->batches) {
    std::string batching;
    for (const KindInfo& k : kinds())
      if (k.batches) batching += std::string(batching.empty() ? "" : " and ") + std::string(k.name);
    throw ConvertError(display_name(request.input) + ": only " + batching +
                       " converts several targets together, not " + request.kind);
  }
  // OpenCV reports bad data (and its own limits) by exception; the user sees the file name.
  try {
    return kind->convert(request);
  } catch (const cv::Exception& e) {
    throw ConvertError(display_name(request.input) + ": image processing failed: " +
                       e.err);
  } catch (const std::invalid_argument& e) {
    throw ConvertError(display_name(request.input) + ": " + e.what());
  }
}

}  // namespace atelier
