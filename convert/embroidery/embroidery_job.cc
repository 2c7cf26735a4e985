#include "convert/embroidery/embroidery_job.h"

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/embroidery/coverage.h"
#include "algorithms/embroidery/pipeline.h"
#include "convert/embroidery/embroidery_params.h"
#include "convert/common/display_text.h"
#include "convert/common/image_input.h"
#include "convert/common/output_files.h"
#include "convert/embroidery/dst_writer.h"
#include "convert/embroidery/exp_writer.h"
#include "algorithms/embroidery/stitch_render.h"
#include "convert/embroidery/jef_writer.h"
#include "convert/embroidery/pes_writer.h"
#include "convert/embroidery/thread_palettes.h"
#include "convert/embroidery/thread_sheet.h"

namespace atelier {
namespace fs = std::filesystem;
namespace emb = embroidery;

namespace {

std::string hex_rgb(const cv::Vec3b& bgr) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", bgr[2], bgr[1], bgr[0]);
  return buf;
}

// Paper Fig. 3's colours: long-short blue, satin green, edge red; white is not sewn. Borders
// between regions are drawn dark so each region reads as one.
cv::Mat3b regions_image(const emb::Segmentation& seg) {
  const cv::Vec3b style_bgr[emb::kStyleCount] = {{200, 110, 40}, {70, 170, 60}, {50, 50, 220}};
  cv::Mat3b out(seg.size, cv::Vec3b(255, 255, 255));
  for (int y = 0; y < seg.size.height; ++y)
    for (int x = 0; x < seg.size.width; ++x) {
      const int id = seg.region_id(y, x);
      if (id < 0) continue;
      const bool border = (x + 1 < seg.size.width && seg.region_id(y, x + 1) != id) ||
                          (y + 1 < seg.size.height && seg.region_id(y + 1, x) != id);
      out(y, x) = border ? cv::Vec3b(40, 40, 40)
                         : style_bgr[static_cast<int>(seg.regions[static_cast<size_t>(id)].style)];
    }
  return out;
}

// The input as make_design takes it: grey becomes BGR, and an RGBA image with no transparent
// pixel (alpha >= 128 everywhere) is the same picture as its RGB, so it loses its alpha and
// every stage sees the RGB image (the white-sheet rule included).
cv::Mat design_input(const cv::Mat& image) {
  cv::Mat out;
  if (image.channels() == 1) {
    cv::cvtColor(image, out, cv::COLOR_GRAY2BGR);
    return out;
  }
  if (image.channels() != 4) return image;
  cv::Mat alpha;
  cv::extractChannel(image, alpha, 3);
  if (cv::countNonZero(alpha < 128) > 0) return image;
  cv::cvtColor(image, out, cv::COLOR_BGRA2BGR);
  return out;
}

emb::ReferenceTexture load_texture(const PathAccess& access, const fs::path& image_file,
                                   const fs::path& normal_file, double dpi, const ImageLimits& limits) {
  const std::string name = access.prefix(image_file);
  cv::Mat image = load_image(access, image_file, limits);
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 3 && image.channels() != 4))
    throw ConvertError(name + "not an 8-bit colour PNG or JPEG texture");
  emb::ReferenceTexture t;
  if (image.channels() == 4) {
    cv::Mat channels[4];
    cv::split(image, channels);
    cv::merge(channels, 3, t.color);
    t.alpha = channels[3];
  } else {
    t.color = image;
    t.alpha = cv::Mat1b(image.size(), 255);
  }
  if (access.is_file(normal_file)) {
    cv::Mat normal = to_8bit(load_image(access, normal_file, limits));
    if (normal.channels() == 1) cv::cvtColor(normal, normal, cv::COLOR_GRAY2BGR);
    else if (normal.channels() == 4) cv::cvtColor(normal, normal, cv::COLOR_BGRA2BGR);
    if (normal.empty() || normal.size() != image.size())
      throw ConvertError(access.prefix(normal_file) + "the normal map must be a colour "
                         "image of the same size as " + display_name(image_file));
    t.normal = normal;
  } else {
    t.normal = cv::Mat3b(image.size(), cv::Vec3b(255, 128, 128));  // flat, BGR of (128,128,255)
  }
  t.width_mm = image.cols * 25.4 / dpi;
  t.height_mm = image.rows * 25.4 / dpi;
  try {
    emb::validate_texture(t);
  } catch (const std::invalid_argument& e) {
    throw ConvertError(name + e.what());
  }
  return t;
}

// JEF's header date, local time, "YYYYMMDDhhmmss".
std::string jef_date() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  localtime_r(&now, &tm);
  char buf[16];
  std::strftime(buf, sizeof buf, "%Y%m%d%H%M%S", &tm);
  return buf;
}

// The sheet's blocks, each with the threads design.pes and design.jef name for it (the same
// assignment the writers make), so the operator loads what the machine's screen asks for.
std::vector<ThreadBlock> sheet_blocks(const emb::StitchPlan& plan) {
  std::vector<ThreadBlock> blocks = thread_blocks(plan);
  const std::vector<std::uint32_t> colors = emb::block_colors(plan);
  const std::vector<int> pec = emb::assign_threads(emb::pec_threads(), colors);
  const std::vector<int> jef = emb::assign_threads(emb::jef_threads(), colors);
  for (std::size_t i = 0; i < blocks.size() && i < colors.size(); ++i) {
    const emb::Thread& b = emb::pec_threads()[pec[i] - 1];
    const emb::Thread& j = emb::jef_threads()[jef[i] - 1];
    blocks[i].thread = std::string("Brother ") + b.name + "\nJanome " + j.code + " " + j.name;
  }
  return blocks;
}

}  // namespace

LoadedTextures load_textures(const PathAccess& access, const fs::path& given, double dpi,
                             const ImageLimits& limits) {
  const fs::path folder = access.resolve(given);
  if (!access.is_dir(folder)) {
    access.open_dir(folder);  // throws the reason (outside the spool, a symlink, ...)
    access.fail(folder, "the textures folder does not exist");
  }
  const std::vector<std::string> files = access.list_files(folder);
  LoadedTextures out{emb::procedural_textures(), {}};
  for (int s = 0; s < emb::kStyleCount; ++s) {
    const std::string style = emb::style_name(static_cast<emb::Style>(s));
    const fs::path image = folder / (style + ".png");
    out.sources[s] = "procedural";
    if (std::find(files.begin(), files.end(), style + ".png") == files.end()) continue;
    out.set.style[s] = load_texture(access, image, folder / (style + ".normal.png"), dpi, limits);
    out.sources[s] = safe_text(image.string());
  }
  return out;
}

ConvertResult convert_embroidery(const ConvertRequest& req) {
  const EmbroideryParams params = read_embroidery_params(req.params, req.params_source);
  const std::string name = safe_text(req.input.filename().string());  // names are data
  report_progress(req, 0.0);
  const cv::Mat image = load_image(req.input, req.limits);
  if (image.depth() != CV_8U || image.channels() == 2)
    throw ConvertError(name + ": expected an 8-bit grey, colour or colour+alpha image");
  const cv::Mat input = design_input(image);
  LoadedTextures textures{emb::procedural_textures(), {"procedural", "procedural", "procedural"}};
  if (params.textures)
    textures = load_textures(req.paths.access("textures"), *params.textures, params.texture_dpi, req.limits);
  report_progress(req, 0.1);

  emb::Design design;
  try {
    design = emb::make_design(input, textures.set, params.design);
  } catch (const emb::HoopTooSmall& e) {
    throw ConvertError(name + ": " + e.what());
  }
  report_progress(req, 0.8);
  if (emb::stitch_stats(design.plan).stitches == 0)
    throw ConvertError(name + ": nothing to sew: no region of the image is large enough to stitch "
                       "(an empty or white image, or specks under min_region_mm2)");
  design.plan.name = safe_text(req.input.stem().string());

  fs::create_directories(req.output_dir);
  write_output(req.output_dir / "design.dst", emb::write_dst(design.plan));
  write_output(req.output_dir / "design.exp", emb::write_exp(design.plan));
  write_output(req.output_dir / "design.pes", emb::write_pes(design.plan));
  write_output(req.output_dir / "design.jef", emb::write_jef(design.plan, jef_date()));
  write_output_png(req.output_dir / "preview.png", design.synthesis.preview);
  write_output_png(req.output_dir / "normal.png", design.synthesis.normal);
  write_output_png(req.output_dir / "regions.png", regions_image(design.segmentation));
  // What the machine sews, drawn from the plan in the preview's frame (they overlay), and the
  // operator's colour sheet with that picture.
  emb::StitchRenderParams render;
  render.size = design.work_size;
  render.px_per_mm = design.px_per_mm;
  render.fabric_bgr = params.design.synthesis.fabric_bgr;
  const emb::StitchRender stitches = emb::render_stitches(design.plan, render);
  write_output_png(req.output_dir / "stitches.png", stitches.image);
  const emb::StitchStats plan_stats = emb::stitch_stats(design.plan);
  write_thread_sheet({name, design.width_mm, design.height_mm, plan_stats.stitches, plan_stats.trims,
                      sheet_blocks(design.plan), stitches.image},
                     req.output_dir / "threads.pdf");

  const emb::Segmentation& seg = design.segmentation;
  const double mm2_per_px = 1.0 / (design.px_per_mm * design.px_per_mm);
  nlohmann::json styles = nlohmann::json::object();
  for (int s = 0; s < emb::kStyleCount; ++s)
    styles[emb::style_name(static_cast<emb::Style>(s))] = {{"count", 0}, {"area_mm2", 0.0}};
  for (const emb::Region& r : seg.regions) {
    nlohmann::json& e = styles[emb::style_name(r.style)];
    e["count"] = e["count"].get<int>() + 1;
    e["area_mm2"] = e["area_mm2"].get<double>() + r.area_px * mm2_per_px;
  }
  // Stitches per colour block, in sewing order.
  std::vector<int> block_stitches(1, 0);
  for (const emb::StitchPoint& p : design.plan.points) {
    if (p.kind == emb::StitchKind::color_change) block_stitches.push_back(0);
    if (p.kind == emb::StitchKind::stitch) ++block_stitches.back();
  }
  nlohmann::json threads = nlohmann::json::array();
  for (size_t i = 0; i < design.plan.colors_rgb.size(); ++i) {
    const std::uint32_t c = design.plan.colors_rgb[i];
    threads.push_back({{"rgb", hex_rgb(cv::Vec3b(c & 0xff, (c >> 8) & 0xff, (c >> 16) & 0xff))},
                       {"stitches", i < block_stitches.size() ? block_stitches[i] : 0}});
  }
  nlohmann::json palette = nlohmann::json::array();
  for (const cv::Vec3b& c : seg.palette.bgr) palette.push_back(hex_rgb(c));
  const emb::StitchStats st = emb::stitch_stats(design.plan);
  nlohmann::json textures_used = nlohmann::json::object();
  for (int s = 0; s < emb::kStyleCount; ++s)
    textures_used[emb::style_name(static_cast<emb::Style>(s))] = textures.sources[s];
  const emb::StitchParams& sp = params.design.stitches;
  // Thread coverage per style (issue 21): each region's own stitches, regions over 4 mm².
  emb::StitchParams cov_params = sp;
  cov_params.px_per_mm = design.px_per_mm;
  const auto by_style = emb::coverage_by_style(emb::design_coverage(seg, design.directions, cov_params));
  nlohmann::json coverage = nlohmann::json::object();
  for (int s = 0; s < emb::kStyleCount; ++s)
    coverage[emb::style_name(static_cast<emb::Style>(s))] = {
        {"regions", by_style[s].regions}, {"min", by_style[s].min}, {"mean", by_style[s].mean},
        {"regions_below_98", by_style[s].below}};
  nlohmann::json report = {
      {"kind", "embroidery"},
      {"input", name},
      {"size_mm", {design.width_mm, design.height_mm}},
      {"px_per_mm", design.px_per_mm},
      {"work_size_px", {design.work_size.width, design.work_size.height}},
      {"palette", palette},
      {"threads", threads},
      {"regions", {{"total", seg.regions.size()}, {"by_style", styles}}},
      {"components", seg.components},
      {"components_forced_long_short", seg.components_forced_long_short},
      {"stitches", st.stitches},
      {"coverage", coverage},
      {"jumps", st.jumps},
      {"trims", st.trims},
      {"color_changes", st.color_changes},
      {"extent_mm", {{"min_x", st.min_x_mm}, {"max_x", st.max_x_mm},
                     {"min_y", st.min_y_mm}, {"max_y", st.max_y_mm},
                     {"width", st.max_x_mm - st.min_x_mm}, {"height", st.max_y_mm - st.min_y_mm}}},
      {"hoop_mm", {sp.hoop_width_mm, sp.hoop_height_mm}},
      {"files", {"design.dst", "design.exp", "design.pes", "design.jef"}},
      {"textures", textures_used},
  };
  write_output(req.output_dir / "report.json", report.dump(2) + "\n");
  report_progress(req, 1.0);
  return {report, {"design.dst", "design.exp", "design.pes", "design.jef", "preview.png", "stitches.png",
                   "normal.png", "regions.png", "threads.pdf", "report.json"}};
}

}  // namespace atelier
