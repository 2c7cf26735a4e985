#include "convert/knit/knit_order.h"

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "base/error.h"
#include "convert/common/display_text.h"
#include "convert/report_file.h"

namespace atelier {

bool job_knits_top_row_first(const std::filesystem::path& output_dir) {
  const std::filesystem::path file = output_dir / report_file_name();
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) return false;
  std::ifstream in(file);
  if (!in) throw BadInput(file.string() + " cannot be read");
  std::ostringstream text;
  text << in.rdbuf();
  const nlohmann::json report = nlohmann::json::parse(text.str(), nullptr, false);
  if (report.is_discarded() || !report.is_object())
    throw BadInput(file.string() + " is not a JSON object; convert the job again");
  const auto it = report.find("first_row");
  if (it == report.end()) return false;
  if (*it == "top") return true;
  if (*it == "bottom") return false;
  throw BadInput(file.string() + ": first_row is " + display_value(it->dump()) +
                 "; expected \"bottom\" or \"top\"");
}

}  // namespace atelier
