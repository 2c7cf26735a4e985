#include "tools/convert_commands.h"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "algorithms/pencil/profile.h"
#include "algorithms/pencil/reference_scan.h"
#include "algorithms/pencil/strokes.h"
#include "convert/convert.h"
#include "convert/common/display_text.h"
#include "convert/common/image_input.h"
#include "convert/sketch/line_job.h"
#include "convert/common/output_files.h"
#include "convert/common/param_table.h"
#include "convert/sketch/pencil_profile_file.h"

namespace atelier::convert_tool {

namespace fs = std::filesystem;

// Reads a whole TOML file (also /dev/stdin, which cannot be sized or seeked).
toml::table parse_toml_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ParamError(display_path(path) + ": cannot open: " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  try {
    return toml::parse(text.str(), std::string_view{path});
  } catch (const toml::parse_error& e) {
    throw ParamError(toml_error_text(e, path));
  }
}

namespace {

// Prints a ConvertError/ParamError/other failure as the tool does everywhere; returns 1.
int input_error(const std::string& what) {
  std::cerr << "error: " << what << "\n";
  return 1;
}

// A scan as 8-bit grey on white: colour by luminance, transparent pixels as paper (composited
// as sketch jobs do, pencil::on_white_paper).
cv::Mat scan_to_grey(const cv::Mat& image, const std::string& name) {
  cv::Mat eight = image;
  if (image.depth() == CV_16U) image.convertTo(eight, CV_8U, 1.0 / 257);
  else if (image.depth() != CV_8U) throw ConvertError(name + ": expected an 8- or 16-bit image");
  if (eight.channels() != 1 && eight.channels() != 3 && eight.channels() != 4)
    throw ConvertError(name + ": expected a grey, colour or colour+alpha image");
  const cv::Mat paper = atelier::pencil::on_white_paper(eight);
  if (paper.channels() == 1) return paper;
  cv::Mat grey;
  cv::cvtColor(paper, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

}  // namespace

// `atelier-convert pencil-profile`: learns a pencil profile and writes it as TOML.
int run_pencil_profile(int argc, char** argv) {
  CLI::App app{
      "atelier-convert pencil-profile: learn a pencil profile (Meraj et al. 2008, section 3.2) from a scan\n"
      "of lines drawn with one pencil. The lines must run VERTICALLY (rotate the scan first) on white\n"
      "paper; pixels darker than paper_threshold (245) are the line. Use the profile with\n"
      "--set pencil=OUT.toml in sketch and line jobs.\n"
      "  atelier-convert pencil-profile SCAN.png OUT.toml [--set name=NAME] [--set paper_threshold=245]\n"
      "  atelier-convert pencil-profile --reference GRADE OUT.toml [--scan-png SCAN.png]",
      "atelier-convert pencil-profile"};
  std::vector<std::string> files;
  std::vector<std::string> sets;
  std::string reference, scan_png;
  atelier::ImageLimits limits;
  std::vector<std::string> grades;
  for (const auto& m : atelier::pencil::grade_models()) grades.push_back(m.name);
  std::string first, second;
  app.add_option("SCAN.png", first, "the scan: pencil lines running vertically on white paper (with --reference: OUT.toml)")
      ->required();
  app.add_option("OUT.toml", second, "the profile to write (atomically)");
  app.add_option("--set", sets, "name=NAME (default: OUT's stem), paper_threshold=1..255 (default 245)")
      ->allow_extra_args(false);
  app.add_option("--reference", reference,
                 "learn from the modelled reference scan of a shipped grade instead of a SCAN (how the "
                 "shipped profiles are made; see tools/make-pencil-profiles)")
      ->check(CLI::IsMember(grades, CLI::ignore_case));
  app.add_option("--scan-png", scan_png, "with --reference: also write the reference scan as this PNG");
  app.add_option("--max-file-bytes", limits.max_file_bytes, "largest scan file in bytes");
  app.add_option("--max-pixels", limits.max_pixels, "largest scan in pixels");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  files.push_back(first);
  if (!second.empty()) files.push_back(second);
  const size_t want = reference.empty() ? 2 : 1;
  if (files.size() != want || (!scan_png.empty() && reference.empty())) {
    std::cerr << "error: expected " << (reference.empty() ? "SCAN.png OUT.toml" : "--reference GRADE OUT.toml")
              << (!scan_png.empty() && reference.empty() ? " (--scan-png goes with --reference)" : "") << "\n"
              << "Run with --help for more information.\n";
    return 2;
  }
  const fs::path out = files.back();
  try {
    toml::table overrides;
    for (const auto& s : sets) atelier::apply_set(overrides, s);
    atelier::TableReader r(overrides, "--set", "");
    const std::string name = r.get_string("name", reference.empty() ? out.stem().string() : "");
    const int threshold = static_cast<int>(r.get_int("paper_threshold", 245, 1, 255));
    r.finish();
    if (name.empty() && reference.empty()) r.fail("name", "must not be empty");
    cv::Mat grey;
    std::string source;
    std::string profile_name = name;
    if (!reference.empty()) {
      const atelier::pencil::GradeModel* model = nullptr;
      for (const auto& m : atelier::pencil::grade_models())
        if (CLI::detail::to_lower(m.name) == CLI::detail::to_lower(reference)) model = &m;
      grey = atelier::pencil::reference_scan(*model, atelier::pencil::kReferenceRows, atelier::pencil::kReferenceSeed);
      if (profile_name.empty()) profile_name = model->name;
      source = "reference_scan(" + model->name + ", " + std::to_string(atelier::pencil::kReferenceRows) +
               " rows, seed " + std::to_string(atelier::pencil::kReferenceSeed) +
               "): MODELLED lines (algorithms/pencil/reference_scan.h), not a scan of a real pencil";
      if (!scan_png.empty()) atelier::write_output_png(scan_png, grey);
    } else {
      const fs::path scan = files.front();
      grey = scan_to_grey(atelier::load_image(scan, limits), scan.filename().string());
      source = scan.filename().string();
    }
    atelier::pencil::PencilProfile profile;
    try {
      profile = atelier::pencil::learn_profile(grey, profile_name, threshold);
    } catch (const std::invalid_argument&) {
      throw ConvertError(files.front() + ": no pencil line found (darker than " + std::to_string(threshold) +
                         " on white paper)");
    }
    // Never write a profile that sketch and line jobs would refuse: a scan that is all line (no
    // paper beside it) gives one run as wide as the scan, wider than any pencil line.
    const std::string text = atelier::profile_to_toml(profile, source);
    try {
      atelier::profile_from_toml(text, out.string());
    } catch (const ConvertError& e) {
      throw ConvertError(files.front() + ": the profile learned from it would be unusable (is there white paper "
                         "beside the lines?): " + e.what());
    }
    atelier::write_output(out, text);
    std::cout << profile.name << ": centre " << profile.min_mid << ".." << profile.max_mid << ", line "
              << profile.min_range << ".." << profile.max_range << ", width " << profile.width_px << " px, "
              << profile.line_pixels << " line pixels -> " << out.string() << "\n";
  } catch (const ConvertError& e) {
    return input_error(e.what());
  } catch (const ParamError& e) {
    return input_error(e.what());
  } catch (const std::exception& e) {
    return input_error(files.front() + ": " + e.what());
  }
  return 0;
}

// `atelier-convert line - OUTPUT_DIR --set from=X,Y --set to=X,Y ...`: one hand-drawn line.
int run_line(int argc, char** argv) {
  CLI::App app{
      "atelier-convert line: draw one hand-drawn pencil line between two end points (Meraj et al.\n"
      "2008): writes line.png, line.json (the path) and report.json into OUTPUT_DIR.\n"
      "Parameters (--set key=value): from=X,Y and to=X,Y (px, required), pencil=2H..8B or a .toml\n"
      "profile (HB), squiggle=D px (5), seed=N (1), margin=px (20).",
      "atelier-convert line"};
  std::string input, output_dir, params_file;
  std::vector<std::string> sets;
  atelier::ImageLimits limits;
  app.add_option("INPUT", input, "\"-\" (a line has no input file)")->required();
  app.add_option("OUTPUT_DIR", output_dir, "folder for the outputs (created if missing)")->required();
  app.add_option("--params", params_file, "TOML file of parameters (applied first)");
  app.add_option("--set", sets, "one parameter, key=value (repeatable)")->allow_extra_args(false);
  app.add_option("--max-pixels", limits.max_pixels, "largest canvas in pixels");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  if (input != "-") {
    std::cerr << "error: line takes \"-\" as INPUT (its end points are parameters: --set from=X,Y --set to=X,Y)\n"
              << "Run with --help for more information.\n";
    return 2;
  }
  try {
    toml::table params;
    if (!params_file.empty()) atelier::merge_into(params, parse_toml_file(params_file));
    toml::table overrides;
    for (const auto& s : sets) atelier::apply_set(overrides, s);
    atelier::merge_into(params, overrides);
    atelier::convert_line(params, "--set", output_dir, limits);  // its only parameters: name them as the kinds do
  } catch (const ConvertError& e) {
    return input_error(e.what());
  } catch (const ParamError& e) {
    return input_error(e.what());
  } catch (const std::exception& e) {
    return input_error(std::string("line: ") + e.what());
  }
  return 0;
}

}  // namespace atelier::convert_tool
