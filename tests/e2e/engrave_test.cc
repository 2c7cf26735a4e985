// End to end: a photo dropped into incoming/engrave/ becomes a raster engraving (job.gcode,
// preview.png, report.json) that waits for the operator; started, the GRBL laser emulator burns
// what the preview shows: the SSIM of the emulator's render against preview.png, at the
// preview's resolution, is at least 0.9 for two dithering modes and for greyscale power.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "tests/e2e/daemon_harness.h"

namespace fs = std::filesystem;
using atelier::test::BackgroundProcess;
using atelier::test::DaemonProcess;
using atelier::test::TempDir;
using nlohmann::json;

namespace {

// The emulator draws every burn max(1, round(0.2 mm * ppm)) px wide: at 40 px/mm one 0.2 mm
// scan line is 8 px high and a run's drawn end spills 1 px (1/8 dot) past its last dot.
constexpr double kRenderPxPerMm = 40;
constexpr double kBedMm = 150;

// SSIM of Wang, Bovik, Sheikh & Simoncelli (2004): 11x11 Gaussian window, sigma 1.5,
// K1 = 0.01, K2 = 0.03, L = 255; the mean over the image.
double ssim(const cv::Mat& a8, const cv::Mat& b8) {
  cv::Mat a, b;
  a8.convertTo(a, CV_64F);
  b8.convertTo(b, CV_64F);
  const double c1 = std::pow(0.01 * 255, 2), c2 = std::pow(0.03 * 255, 2);
  auto blur = [](const cv::Mat& m) {
    cv::Mat out;
    cv::GaussianBlur(m, out, {11, 11}, 1.5);
    return out;
  };
  const cv::Mat mu_a = blur(a), mu_b = blur(b);
  const cv::Mat aa = blur(a.mul(a)) - mu_a.mul(mu_a), bb = blur(b.mul(b)) - mu_b.mul(mu_b);
  const cv::Mat ab = blur(a.mul(b)) - mu_a.mul(mu_b);
  cv::Mat num = (2 * mu_a.mul(mu_b) + c1).mul(2 * ab + c2);
  cv::Mat den = (mu_a.mul(mu_a) + mu_b.mul(mu_b) + c1).mul(aa + bb + c2);
  cv::Mat map;
  cv::divide(num, den, map);
  return cv::mean(map)[0];
}

struct Engraving {
  const char* name;
  const char* dither;
  double y_mm;  // front edge, mm from the bed's front
};

}  // namespace

TEST(E2EEngrave, APhotoIsBurnedAsThePreviewShowsForDitheredAndGreyscalePower) {
  TempDir tmp;
  // Time scale 0.5, not the 0.005 of the vector tests: the emulator's motion is GRBL's planner
  // and M4 power follows the real speed, so a host that cannot stream 200x faster than the link
  // starves the 15-block buffer and the head slows (lighter burns; SSIM 0.27 at 0.005, 0.5-0.8
  // at 0.1). At 0.5 the burn is what an operator gets when streaming keeps up.
  const fs::path link = tmp.path() / "laser", record = tmp.path() / "record.json", render = tmp.path() / "burn.png";
  BackgroundProcess emulator({atelier::test::binary("atelier-laser-emu").string(), "--link", link.string(),
                              "--record", record.string(), "--render", render.string(), "--px-per-mm",
                              std::to_string(kRenderPxPerMm), "--work-area", "150x150", "--time-scale", "0.5"},
                             tmp.path() / "emu.log");
  for (int i = 0; i < 100 && !fs::exists(link); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  // 30 mm wide at 127 dpi (0.2 mm dots) and 0.2 mm lines: 150 x 108 dots each.
  DaemonProcess daemon(tmp.path(), "[engrave]\nwidth_mm = 20\ndpi = 127\nline_interval_mm = 0.2\n"
                                   "[laser]\nwork_area_mm = [150, 150]\n"
                                   "[[device]]\nname = \"laser\"\ndriver = \"grbl\"\nport = \"" + link.string() +
                                       "\"\nkinds = [\"engrave\"]\n");
  daemon.start();

  const Engraving engravings[] = {{"fs.jpg", "floyd-steinberg", 10}, {"bayer.jpg", "ordered", 50},
                                  {"grey.jpg", "greyscale", 90}};
  std::vector<json> reports;
  std::vector<cv::Mat> previews;
  for (const Engraving& e : engravings) {
    atelier::test::write_file(daemon.incoming("engrave") / (std::string(e.name) + ".toml"),
                              "dither = \"" + std::string(e.dither) + "\"\nposition_mm = [10, " +
                                  std::to_string(e.y_mm) + "]\n");
    atelier::test::drop_file(atelier::test::test_image("butterfly.jpg"), daemon.incoming("engrave") / e.name);
    ASSERT_TRUE(daemon.wait_job_state(e.name, "ready")) << daemon.job_named(e.name).dump() << daemon.log();
    const json job = daemon.job_named(e.name);
    const fs::path done = job["output_dir"].get<std::string>();
    for (const char* f : {"preview.png", "job.gcode", "report.json"}) EXPECT_TRUE(fs::exists(done / f)) << f;
    reports.push_back(json::parse(std::ifstream(done / "report.json")));
    EXPECT_EQ(reports.back()["dither"], e.dither);
    previews.push_back(cv::imread((done / "preview.png").string(), cv::IMREAD_GRAYSCALE));
    ASSERT_EQ(previews.back().cols, 100) << "20 mm at 127 dpi";
    // A laser job waits for the operator; started, it burns.
    ASSERT_TRUE(daemon.request("start", {{"id", job["id"]}})["ok"]);
    ASSERT_TRUE(daemon.wait_job_state(e.name, "completed", std::chrono::seconds(240)))
        << daemon.job_named(e.name).dump() << daemon.log();
  }
  emulator.stop();
  const json rec = json::parse(std::ifstream(record));
  EXPECT_EQ(rec["errors"], 0);
  const cv::Mat burnt = cv::imread(render.string(), cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(burnt.cols, static_cast<int>(kBedMm * kRenderPxPerMm));

  std::vector<cv::Mat> seens;
  for (size_t i = 0; i < previews.size(); ++i) {
    SCOPED_TRACE(engravings[i].dither);
    const cv::Mat& preview = previews[i];
    const double w = reports[i]["size_mm"][0], h = reports[i]["size_mm"][1];
    // The engraving's area in the render: X 10..10+w, Y y..y+h (pixel rows from the rear).
    const cv::Rect area(static_cast<int>(std::lround(10 * kRenderPxPerMm)),
                        static_cast<int>(std::lround((kBedMm - engravings[i].y_mm - h) * kRenderPxPerMm)),
                        static_cast<int>(std::lround(w * kRenderPxPerMm)),
                        static_cast<int>(std::lround(h * kRenderPxPerMm)));
    cv::Mat seen;
    cv::resize(burnt(area), seen, preview.size(), 0, 0, cv::INTER_AREA);
    cv::imwrite((tmp.path() / (std::string("seen-") + engravings[i].name + ".png")).string(), seen);
    const double s = ssim(seen, preview);
    std::cout << engravings[i].dither << ": SSIM " << s << ", estimated " << reports[i]["estimated_time_s"]
              << " s, " << reports[i]["gcode_lines"] << " lines, stream " << reports[i]["stream"].dump() << "\n";
    EXPECT_GE(s, 0.9) << "the burn differs from preview.png";
    // Not a blank match: the photo was burned (a fifth of the area at least darkened).
    EXPECT_GT(cv::countNonZero(seen < 230), preview.total() / 5);
    seens.push_back(seen);
  }
  // The measure tells the modes apart: each burn against another mode's preview (the same
  // photo, other dots) scores well below the bar.
  ASSERT_EQ(seens.size(), 3u);
  for (size_t i = 0; i < 3; ++i)
    for (size_t j = 0; j < 3; ++j)
      if (i != j) {
        const double s = ssim(seens[i], previews[j]);
        std::cout << "burn " << engravings[i].dither << " vs preview " << engravings[j].dither << ": SSIM " << s << "\n";
        EXPECT_LT(s, 0.9) << engravings[i].dither << " vs " << engravings[j].dither;
      }
  if (const char* keep = std::getenv("ATELIER_KEEP_ENGRAVE_RENDERS")) {
    std::error_code ec;
    fs::create_directories(keep, ec);
    for (const auto& f : fs::directory_iterator(tmp.path()))
      if (f.path().extension() == ".png") fs::copy_file(f.path(), fs::path(keep) / f.path().filename(), fs::copy_options::overwrite_existing, ec);
  }
}
