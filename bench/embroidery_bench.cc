// Embroidery benchmark (issue 6): the whole design (segmentation + graph-cut labelling,
// synthesis of preview and normal map, machine stitches) at the paper's table-1 sizes.
// The paper: 0.88 s for 388x272 (170 regions), 6.4 s for 600x400, 21.4 s for 1600x1600 on a
// 3.6 GHz CPU with OpenMP. Target: 10x faster on 2 cores; 1600x1600 under 2 s.
// Each case prints its size, region count and stitch count. Images are real photographs and
// a painting from tests/data resized to the size. BM_EmbroideryDesign works on every pixel
// (the design is 10 px per mm, the files' unit, so nothing is resampled), on a hoop large
// enough for it; BM_EmbroideryDefault is what a user gets dropping the image for a 100 mm
// design with the other parameters at their defaults (the pipeline works at most at 10 px/mm:
// 1000x1000 for a 1600 px image). BM_EmbroideryStage times one stage of that default case on
// its own (the design is made once, outside the timing): synthesis (the paper's preview),
// plan (the machine's stitches) and render (stitches.png from the plan); segmentation is the
// rest of BM_EmbroideryDefault's total.
#include <benchmark/benchmark.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <map>
#include <stdexcept>
#include <string>

#include "algorithms/embroidery/directions.h"
#include "algorithms/embroidery/pipeline.h"
#include "algorithms/embroidery/stitch_render.h"

namespace {

namespace emb = atelier::embroidery;

const char* const kImages[] = {"HappyFish.jpg", "fruits.jpg", "starry_night.jpg"};

cv::Mat image(int which, int cols, int rows) {
  const std::string path = std::string(ATELIER_TEST_DATA) + "/" + kImages[which];
  cv::Mat m = cv::imread(path, cv::IMREAD_COLOR);
  if (m.empty()) throw std::runtime_error("embroidery_bench: cannot read " + path);
  cv::resize(m, m, cv::Size(cols, rows), 0, 0, cols > m.cols ? cv::INTER_CUBIC : cv::INTER_AREA);
  return m;
}

// Runs make_design on `state`'s image (args: columns, rows, image index) with `p`, and
// reports its size, regions, stitches and working size.
void run_design(benchmark::State& state, const emb::DesignParams& p) {
  const int cols = static_cast<int>(state.range(0)), rows = static_cast<int>(state.range(1));
  const cv::Mat img = image(static_cast<int>(state.range(2)), cols, rows);
  const emb::TextureSet textures = emb::procedural_textures();
  size_t regions = 0, stitches = 0;
  cv::Size work;
  for (auto _ : state) {
    const emb::Design d = emb::make_design(img, textures, p);
    regions = d.segmentation.regions.size();
    stitches = static_cast<size_t>(emb::stitch_stats(d.plan).stitches);
    work = d.work_size;
    benchmark::DoNotOptimize(d.synthesis.preview.data);
  }
  state.counters["regions"] = static_cast<double>(regions);
  state.counters["stitches"] = static_cast<double>(stitches);
  state.SetLabel(std::to_string(cols) + "x" + std::to_string(rows) + " " + kImages[state.range(2)] +
                 " worked at " + std::to_string(work.width) + "x" + std::to_string(work.height));
}

// Every pixel: 10 px per mm (nothing resampled), on a 400 mm hoop.
void BM_EmbroideryDesign(benchmark::State& state) {
  emb::DesignParams p;
  p.width_mm = static_cast<double>(state.range(0)) / 10.0;
  p.stitches.hoop_width_mm = p.stitches.hoop_height_mm = 400;
  run_design(state, p);
}

// 100 mm wide, other parameters default, on a 130 mm hoop.
void BM_EmbroideryDefault(benchmark::State& state) {
  emb::DesignParams p;
  p.width_mm = 100;
  p.stitches.hoop_width_mm = p.stitches.hoop_height_mm = 130;
  run_design(state, p);
}

// The default 1600x1600 design of `which`, made once per process and image.
const emb::Design& default_design(int which) {
  static std::map<int, emb::Design> made;
  auto it = made.find(which);
  if (it == made.end()) {
    emb::DesignParams p;
    p.width_mm = 100;
    p.stitches.hoop_width_mm = p.stitches.hoop_height_mm = 130;
    it = made.emplace(which, emb::make_design(image(which, 1600, 1600), emb::procedural_textures(), p)).first;
  }
  return it->second;
}

// args: stage (0 synthesis, 1 plan, 2 render), image index.
void BM_EmbroideryStage(benchmark::State& state) {
  const int stage = static_cast<int>(state.range(0)), which = static_cast<int>(state.range(1));
  const emb::Design& d = default_design(which);
  const emb::TextureSet textures = emb::procedural_textures();
  emb::DesignParams dp;
  emb::SynthesisParams sp = dp.synthesis;
  sp.px_per_mm = d.px_per_mm;
  sp.dilate_px = static_cast<int>(std::lround(dp.overlap_mm * d.px_per_mm));
  emb::StitchParams st = dp.stitches;
  st.px_per_mm = d.px_per_mm;
  st.hoop_width_mm = st.hoop_height_mm = 130;
  emb::StitchRenderParams rp;
  rp.size = d.work_size;
  rp.px_per_mm = d.px_per_mm;
  for (auto _ : state) {
    switch (stage) {
      case 0: benchmark::DoNotOptimize(emb::synthesize(d.segmentation, d.directions, textures, sp).preview.data); break;
      case 1: benchmark::DoNotOptimize(emb::plan_stitches(d.segmentation, d.directions, st).points.data()); break;
      case 2: benchmark::DoNotOptimize(emb::render_stitches(d.plan, rp).image.data); break;
    }
  }
  static const char* const kStage[] = {"synthesis", "plan", "render"};
  state.SetLabel(std::string(kStage[stage]) + " of 1600x1600 " + kImages[which] + " worked at " +
                 std::to_string(d.work_size.width) + "x" + std::to_string(d.work_size.height));
}

BENCHMARK(BM_EmbroideryStage)
    ->ArgsProduct({{0, 1, 2}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

// Colour extraction alone (issue 21 point 4: k-means, distinct patches over every pixel, the
// thread means) on the working image BM_EmbroideryDefault gets from a 1600 px image.
void BM_EmbroideryColors(benchmark::State& state) {
  const cv::Mat img = image(static_cast<int>(state.range(2)), static_cast<int>(state.range(0)),
                            static_cast<int>(state.range(1)));
  emb::ColorParams cp;
  cp.min_area_px = 100;  // min_region_mm2 = 1 at 10 px/mm
  size_t colors = 0;
  for (auto _ : state) {
    const emb::ColorExtraction ce = emb::extract_colors(img, cp);
    colors = ce.palette.bgr.size();
    benchmark::DoNotOptimize(ce.color_index.data);
  }
  state.counters["colors"] = static_cast<double>(colors);
  state.SetLabel(std::to_string(img.cols) + "x" + std::to_string(img.rows) + " " + kImages[state.range(2)]);
}

BENCHMARK(BM_EmbroideryColors)
    ->Args({1000, 1000, 0})
    ->Args({1000, 1000, 1})
    ->Args({1000, 1000, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

BENCHMARK(BM_EmbroideryDefault)
    ->Args({1600, 1600, 0})
    ->Args({1600, 1600, 1})
    ->Args({1600, 1600, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);

BENCHMARK(BM_EmbroideryDesign)
    ->Args({388, 272, 0})
    ->Args({388, 272, 2})
    ->Args({600, 400, 1})
    ->Args({600, 400, 2})
    ->Args({875, 739, 2})
    ->Args({1600, 1600, 0})
    ->Args({1600, 1600, 1})
    ->Args({1600, 1600, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);

}  // namespace
