#include "convert/parquetry/parquetry_job.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <set>

#include "algorithms/laser/plan.h"
#include "algorithms/parquetry/memory_estimate.h"
#include "algorithms/parquetry/plan.h"
#include "algorithms/parquetry/render.h"
#include "convert/common/output_files.h"
#include "convert/common/param_table.h"
#include "convert/parquetry/parquetry_params.h"
#include "convert/parquetry/parquetry_svg.h"
#include "convert/common/display_text.h"
#include "inventory/stock_store.h"
#include "inventory/wood_library.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

double round3(double v) { return std::round(v * 1000) / 1000; }

double ms_since(Clock::time_point t) {
  return round3(std::chrono::duration<double, std::milli>(Clock::now() - t).count());
}

json polygon_json(const std::vector<cv::Point2d>& poly) {
  json a = json::array();
  for (const auto& p : poly) a.push_back({round3(p.x), round3(p.y)});
  return a;
}

struct Target {
  fs::path input, output_dir;
  std::string job;  // stock label
  cv::Mat image;
};

// The folder's own name, also for "out/" and "out/.".
std::string folder_name(const fs::path& dir) {
  fs::path p = fs::absolute(dir).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  return p.filename().string();
}

// The laser layers the parquetry program uses: engrave IDs on #0000ff, cut on #ff0000.
struct Layers {
  laser::LayerSettings engrave, cut;
};

Layers laser_layers(const LaserParams& lp, double kerf_mm, const std::string& source) {
  const laser::LayerSettings* cut = layer_for_color(lp, kParquetryCutColor);
  const laser::LayerSettings* engrave = layer_for_color(lp, kParquetryEngraveColor);
  if (!cut || cut->mode != laser::Mode::cut) {
    throw ConvertError(source + ": parquetry cuts its pieces on the laser layer of colour " +
                       std::string(kParquetryCutColor) + " (mode cut); configure a [[laser.layer]] "
                       "with color = \"#ff0000\" and mode = \"cut\"");
  }
  if (!engrave || engrave->mode != laser::Mode::engrave) {
    throw ConvertError(source + ": parquetry engraves piece IDs on the laser layer of colour " +
                       std::string(kParquetryEngraveColor) + " (mode engrave); configure a "
                       "[[laser.layer]] with color = \"#0000ff\" and mode = \"engrave\"");
  }
  Layers l{*engrave, *cut};
  l.cut.kerf_mm = kerf_mm;  // the plan already keeps kerf_mm between pieces: cut outside them
  return l;
}

// Where a sheet lies on the bed: face down, its mirrored frame (the cut file) at the origin
// of the laser's design coordinates (laser/plan.h: the bed's rear-left corner, x right, y
// towards the front), like any SVG cut there. `margin` keeps it off the bed's edges: a piece
// at the sheet's edge is cut kerf/2 outside it, and the work area must hold that path too.
struct Placement {
  double x0 = 0, y0 = 0;
};

double bed_margin(double kerf_mm) { return kerf_mm + 0.05; }

Placement place(double margin) { return {margin, margin}; }

laser::Job sheet_job(const SheetCuts& cuts, const Placement& at, const Layers& layers,
                     const LaserParams& lp) {
  laser::Layer engrave{layers.engrave, {}}, cut{layers.cut, {}};
  for (const PieceCut& p : cuts.pieces) {
    if (p.outline.empty()) {
      throw laser::PlanError("piece " + std::to_string(p.id) + " has no outline");
    }
    for (laser::Path stroke : p.id_text) {
      for (auto& q : stroke.points) q = {q.x + at.x0, q.y + at.y0};
      engrave.paths.push_back(std::move(stroke));
    }
    laser::Path outline;
    outline.closed = true;
    auto shift = [&](cv::Point2d q) { return laser::Point{q.x + at.x0, q.y + at.y0}; };
    outline.points.push_back(shift(p.outline.front().p0));
    for (const auto& c : p.outline) {
      laser::flatten_cubic(shift(c.p0), shift(c.c1), shift(c.c2), shift(c.p3), lp.tolerance_mm,
                           outline.points);
    }
    if (outline.points.size() > 1) outline.points.pop_back();  // closing point is implied
    cut.paths.push_back(std::move(outline));
  }
  return laser::plan_job({engrave, cut}, lp.machine);
}

json params_json(const ParquetryParams& p, const std::vector<SheetEntry>& wood) {
  const parquetry::Params& q = p.plan;
  json w;
  if (p.wood_folder) {
    w = safe_text(p.wood_folder->string());
  } else {
    w = json::array();
    for (const auto& e : wood) w.push_back(e.id);
  }
  return {{"wood", w},
          {"dpi", p.dpi},
          {"size_mm", q.size_mm},
          {"patch_mm", q.patch_mm},
          {"rotations", q.rotations},
          {"w_intens", q.w_intens},
          {"w_edge", q.w_edge},
          {"w_hist", q.w_hist},
          {"adaptive_levels", q.adaptive_levels},
          {"adaptive_factor", q.adaptive_factor},
          {"order", parquetry::order_name(q.order)},
          {"grid", parquetry::grid_name(q.grid)},
          {"refine", parquetry::refine_name(q.refine)},
          {"overlap", q.overlap},
          {"kerf_mm", q.kerf_mm},
          {"min_feature_mm", q.min_feature_mm},
          {"seed", q.seed},
          {"px_per_mm", q.px_per_mm},
          {"working_px_per_mm", parquetry::working_px_per_mm(q)},
          {"stock", p.stock_dir ? json(safe_text(p.stock_dir->string())) : json(nullptr)}};
}

const parquetry::Sheet& sheet_by_id(const std::vector<parquetry::Sheet>& sheets, const std::string& id) {
  for (const auto& s : sheets)
    if (s.id == id) return s;
  throw ConvertError("parquetry: the plan names an unknown sheet '" + id + "'");
}

// Writes one target's outputs; returns its report.
json write_target(const Target& t, const parquetry::Plan& plan,
                  const std::vector<parquetry::Sheet>& sheets, const parquetry::Stock& stock_after,
                  const ParquetryParams& p, const std::vector<SheetEntry>& wood, const Layers& layers,
                  double plan_ms, std::vector<std::string>& outputs) {
  const Clock::time_point start = Clock::now();
  const std::string input_name = safe_text(t.input.filename().string());  // names are data
  const laser::Machine& m = p.laser.machine;

  // The sheets this plan uses, by id (also the cutting order).
  std::set<std::string> used_ids;
  for (const auto& piece : plan.pieces) used_ids.insert(piece.sheet_id);
  std::vector<SheetCuts> cuts;
  std::vector<Placement> places;
  for (const auto& id : used_ids) {
    cuts.push_back(sheet_cuts(plan, sheet_by_id(sheets, id)));
    const SheetCuts& c = cuts.back();
    const double margin = bed_margin(p.plan.kerf_mm);
    if (c.width_mm + 2 * margin > m.width_mm || c.height_mm + 2 * margin > m.height_mm) {
      throw ConvertError(input_name + ": sheet '" + id + "' is " + laser::format_number(c.width_mm) +
                         " x " + laser::format_number(c.height_mm) + " mm, larger than the laser's " +
                         laser::format_number(m.width_mm) + " x " + laser::format_number(m.height_mm) +
                         " mm work area; cut the board down and scan it again");
    }
    places.push_back(place(margin));
  }

  // One program: each sheet engraved then cut, a program pause between sheets.
  std::vector<laser::Job> jobs;
  std::vector<std::vector<std::string>> notes;
  for (size_t i = 0; i < cuts.size(); ++i) {
    try {
      jobs.push_back(sheet_job(cuts[i], places[i], layers, p.laser));
    } catch (const laser::PlanError& e) {
      throw ConvertError(input_name + ": sheet '" + cuts[i].sheet_id + "': " + e.what());
    }
    const std::string& id = cuts[i].sheet_id;
    // The driver shows the comment just before an M0 to the operator: the instruction last.
    notes.push_back({"sheet " + id + ": its top-right corner as scanned (face up) goes in the "
                     "bed's rear-left corner",
                     "sheet " + id + ": place it face down at the origin" +
                         (i == 0 ? std::string(" before starting") : std::string(", then resume"))});
  }
  laser::Job program;
  if (!jobs.empty()) {
    try {
      program = laser::join_jobs(jobs, notes, m);
    } catch (const laser::PlanError& e) {
      throw ConvertError(input_name + ": " + e.what());
    }
  }

  std::error_code ec;
  fs::create_directories(t.output_dir, ec);
  if (ec) throw ConvertError(t.output_dir.string() + ": cannot create output folder: " + ec.message());
  const fs::path& out = t.output_dir;

  // plan.json
  json pieces = json::array();
  for (const auto& piece : plan.pieces) {
    pieces.push_back({{"id", piece.id},
                      {"wood", piece.sheet_id},
                      {"rotation_deg", round3(piece.rotation_deg)},
                      {"source", polygon_json(piece.source_mm)},
                      {"target", polygon_json(piece.target_mm)},
                      {"cost", piece.cost},
                      {"level", piece.level}});
  }
  json sheet_list = json::array();
  for (size_t i = 0; i < cuts.size(); ++i) {
    json ids = json::array();
    for (const auto& pc : cuts[i].pieces) ids.push_back(pc.id);
    sheet_list.push_back({{"id", cuts[i].sheet_id},
                          {"width_mm", round3(cuts[i].width_mm)},
                          {"height_mm", round3(cuts[i].height_mm)},
                          {"cuts", "cuts-" + cuts[i].sheet_id + ".svg"},
                          {"pieces", ids},
                          {"bed", {{"face_down", true},
                                   {"mirrored", true},
                                   {"bed_corner", "rear-left"},
                                   {"scan_corner", "top-right"},
                                   {"x_mm", round3(places[i].x0)},
                                   {"y_mm", round3(places[i].y0)}}}});
  }
  json plan_json = {{"kind", "parquetry"},
                    {"width_mm", round3(plan.width_mm)},
                    {"height_mm", round3(plan.height_mm)},
                    {"grid", parquetry::grid_name(plan.grid)},
                    {"refine", parquetry::refine_name(plan.refine)},
                    {"grid_cols", plan.grid_cols},
                    {"grid_rows", plan.grid_rows},
                    {"job", t.job},
                    {"params", params_json(p, wood)},
                    {"pieces", pieces},
                    {"sheets", sheet_list}};
  write_output(out / "plan.json", plan_json.dump(1) + "\n");
  outputs.push_back("plan.json");

  for (const auto& c : cuts) {
    write_output(out / ("cuts-" + c.sheet_id + ".svg"), cuts_svg(c));
    outputs.push_back("cuts-" + c.sheet_id + ".svg");
  }
  write_output(out / "assembly.svg", assembly_svg(plan));
  outputs.push_back("assembly.svg");
  if (!jobs.empty()) {
    write_output(out / kParquetryGcodeFile, program.gcode);
    outputs.push_back(kParquetryGcodeFile);
  }
  cv::Mat preview = parquetry::render_plan(plan, sheets);
  write_output_png(out / "preview.png", preview);
  outputs.push_back("preview.png");

  // report.json
  json sheet_report = json::array();
  for (const auto& id : used_ids) {
    const parquetry::Sheet& sheet = sheet_by_id(sheets, id);
    int n = 0;
    double used = 0;
    for (const auto& piece : plan.pieces) {
      if (piece.sheet_id != id) continue;
      ++n;
      used += std::abs(parquetry::polygon_area(piece.source_mm));
    }
    const double free_after = parquetry::free_area_mm2({sheet}, stock_after, parquetry::working_px_per_mm(p.plan), p.plan.kerf_mm);
    sheet_report.push_back({{"id", id}, {"pieces", n}, {"used_mm2", round3(used)}, {"free_mm2", round3(free_after)}});
  }
  json splits = json::array();
  int split_count = 0;
  for (const auto& s : plan.splits) {
    split_count += s.split ? 1 : 0;
    splits.push_back({{"target_mm", {round3(s.target_mm.x), round3(s.target_mm.y), round3(s.target_mm.width),
                                     round3(s.target_mm.height)}},
                      {"whole_cost", s.whole_cost},
                      {"quarters_cost", s.quarters_cost},
                      {"split", s.split}});
  }
  json sheets_order = json::array();
  for (const auto& id : used_ids) sheets_order.push_back(id);
  json r = {{"kind", "parquetry"},
            {"input", {{"file", input_name}}},
            {"job", t.job},
            {"pieces", plan.pieces.size()},
            {"grid_cols", plan.grid_cols},
            {"grid_rows", plan.grid_rows},
            {"width_mm", round3(plan.width_mm)},
            {"height_mm", round3(plan.height_mm)},
            {"sheets", sheet_report},
            {"error", plan.error},
            {"baseline_error", plan.baseline_error},
            {"target_mean_error", plan.target_mean_error},
            {"ssim", plan.ssim}};
  if (plan.refine == parquetry::Refine::dp) {
    r["seam_cost_straight"] = plan.seam_cost_straight;
    r["seam_cost_refined"] = plan.seam_cost_refined;
    r["seams_refined"] = plan.seams_refined;
    r["seams_straightened"] = plan.seams_straightened;
    r["curves_cut"] = plan.curves_cut;
  }
  r["splits"] = split_count;
  r["split_decisions"] = splits;
  r["laser"] = {{"estimated_time_s", round3(program.estimated_s)},
                {"cut_length_mm", round3(program.cut_length_mm)},
                {"engrave_length_mm", round3(program.engrave_length_mm)},
                {"travel_length_mm", round3(program.travel_length_mm)},
                {"bounds_mm", {{"min_x", round3(program.bounds.min_x)},
                               {"min_y", round3(program.bounds.min_y)},
                               {"max_x", round3(program.bounds.max_x)},
                               {"max_y", round3(program.bounds.max_y)}}},
                {"work_area_mm", {m.width_mm, m.height_mm}},
                {"coordinates", "bed"},
                {"s_max", m.s_max},
                {"cut_kerf_mm", layers.cut.kerf_mm}};
  r["sheets_order"] = sheets_order;
  r["preview_px_per_mm"] = round3(parquetry::render_px_per_mm(plan, {}));
  r["params"] = params_json(p, wood);
  r["timings_ms"] = {{"plan", plan_ms}, {"outputs", ms_since(start)}};
  outputs.push_back("report.json");
  r["outputs"] = outputs;
  write_output(out / "report.json", r.dump(2) + "\n");
  return r;
}

// "3.1 GB" / "640 MB".
std::string megabytes(double bytes) {
  const double mb = bytes / (1 << 20);
  char buf[32];
  if (mb >= 1024) std::snprintf(buf, sizeof buf, "%.1f GB", mb / 1024);
  else std::snprintf(buf, sizeof buf, "%.0f MB", mb);
  return buf;
}

// Refuses a plan whose estimated peak memory is above the budget, before anything is matched
// (the scans' sizes from their headers, the targets' from the decoded images).
void check_memory_budget(const std::vector<Target>& targets, const std::vector<SheetEntry>& wood,
                         const ParquetryParams& p, const PathAccess& access, uint64_t budget_mb) {
  if (budget_mb == 0) return;
  std::vector<parquetry::SheetSize> sheets;
  for (const SheetEntry& e : wood) {
    // A scan this job may not open, or that is no image, is load_sheets' to report.
    if (!access.is_file(e.image)) continue;
    try {
      const ImageHeader h = probe_image(e.image);
      sheets.push_back({cv::Size(static_cast<int>(h.width), static_cast<int>(h.height)), e.dpi,
                        !e.mask.empty()});
    } catch (const ConvertError&) {
    }
  }
  std::vector<cv::Size> sizes;
  for (const Target& t : targets) sizes.push_back(t.image.size());
  const parquetry::MemoryEstimate e = parquetry::estimate_plan_memory(sheets, sizes, p.plan);
  if (e.total_bytes <= static_cast<double>(budget_mb) * (1 << 20)) return;
  throw ConvertError(safe_text(targets.front().input.filename().string()) + ": the parquetry plan needs about " +
                     megabytes(e.total_bytes) + " (" + parquetry::memory_drivers(sheets, p.plan) +
                     "), above the " + std::to_string(budget_mb) +
                     " MB budget (limits.job_memory_mb); lower px_per_mm or rotations, or use fewer sheets");
}

}  // namespace

ConvertResult convert_parquetry(const ConvertRequest& req) {
  const std::string& source = req.params_source;
  const ParquetryParams p = read_parquetry_params(req.params, source);
  // The stock is workshop state: a job (sidecar, job file, --set) run by the daemon may not
  // choose where it lives, and the converter creates no stock folder for it.
  if (req.paths.confined() && req.paths.from_job("stock")) {
    throw ParamError(display_path(req.paths.source_of("stock")) +
                     ": key 'stock': a job may not choose the stock folder (the workshop's used "
                     "wood, [parquetry] stock in the daemon's config)");
  }
  const PathAccess wood_access = req.paths.access("wood");
  const std::vector<SheetEntry> wood = require_wood(p, source, wood_access);
  if (wood.empty()) {
    throw ConvertError((p.wood_folder ? wood_access.prefix(*p.wood_folder) : source + ": ") +
                       "no veneer scans in the wood library");
  }
  const Layers layers = laser_layers(p.laser, p.plan.kerf_mm, source);
  report_progress(req, 0.0);

  // Stock labels are the output folders' names: the job ids in the daemon, never a user's
  // parameter (a chosen label could name another job's pieces).
  std::vector<Target> targets{{req.input, req.output_dir, folder_name(req.output_dir), {}}};
  for (const auto& extra : req.together) {
    targets.push_back({extra.input, extra.output_dir, folder_name(extra.output_dir), {}});
  }
  std::set<std::string> folders, labels;
  for (Target& t : targets) {
    if (!folders.insert(fs::absolute(t.output_dir).lexically_normal().string()).second) {
      throw ConvertError(t.output_dir.string() + ": two targets write to the same output folder");
    }
    if (!labels.insert(t.job).second) {
      throw ConvertError(t.input.filename().string() + ": two targets have the stock label '" + t.job + "'");
    }
    t.image = to_8bit(load_image(t.input, req.limits));
  }
  check_memory_budget(targets, wood, p, wood_access, req.memory_mb);
  // Held until the new pieces are recorded: no other conversion plans this wood meanwhile,
  // and the scans are read under it (a sheet removed or replaced meanwhile is not planned).
  // A job converted again (retry, crash recovery) plans on new wood: its earlier pieces stay
  // taken, since they may have been cut already (`atelierctl wood reset --job` frees them).
  std::optional<StockLock> lock;
  parquetry::Stock stock;
  if (p.stock_dir) {
    // Run by the daemon (confined), the stock folder must exist: the daemon makes its own.
    lock.emplace(*p.stock_dir, /*create=*/!req.paths.confined());
    stock = load_stock(*p.stock_dir);
  }
  const std::vector<parquetry::Sheet> sheets = load_sheets(wood, req.limits, wood_access);
  report_progress(req, 0.1);

  std::vector<cv::Mat> images;
  for (const Target& t : targets) images.push_back(t.image);
  const std::string first = safe_text(req.input.filename().string());
  std::vector<parquetry::Plan> plans;
  const Clock::time_point plan_start = Clock::now();
  try {
    plans = parquetry::make_plans(images, sheets, stock, p.plan);
  } catch (const parquetry::OutOfWood& e) {
    throw ConvertError(first + ": " + e.what());
  } catch (const parquetry::Unfabricable& e) {
    throw ConvertError(first + ": cannot make cuttable pieces: " + e.what());
  } catch (const std::invalid_argument& e) {
    throw ConvertError(first + ": " + e.what());
  }
  const double plan_ms = ms_since(plan_start);
  report_progress(req, 0.7);

  ConvertResult result;
  parquetry::Stock after = stock;
  for (size_t i = 0; i < targets.size(); ++i) {
    after = parquetry::with_plan(std::move(after), plans[i], targets[i].job);
    std::vector<std::string> outputs;
    json r = write_target(targets[i], plans[i], sheets, after, p, wood, layers, plan_ms, outputs);
    if (i == 0) {
      result.report = nlohmann::json::parse(r.dump());
      result.outputs = outputs;
    }
    report_progress(req, 0.7 + 0.3 * double(i + 1) / double(targets.size()));
  }
  // Only now, with every output written, is the wood taken.
  if (p.stock_dir) save_stock(*p.stock_dir, after, /*create=*/!req.paths.confined());
  report_progress(req, 1.0);
  return result;
}

}  // namespace atelier
