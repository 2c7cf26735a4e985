// End to end: an image dropped into incoming/embroidery/ becomes stitch files in the
// embroidery machine's drop folder (a file-drop device), which decode as DST and EXP and agree
// with the job's report; a missing drop folder fails the next job with its reason and keeps
// its design.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "tests/e2e/daemon_harness.h"
#include "tests/support/stitch_file_readers.h"

namespace fs = std::filesystem;
using atelier::test::DaemonProcess;
using atelier::test::read_file;
using atelier::test::TempDir;
using nlohmann::json;
namespace readers = atelier::embroidery::test;

TEST(E2EEmbroidery, ADroppedImageBecomesStitchFilesInTheMachinesFolder) {
  TempDir tmp;
  const fs::path stick = tmp.path() / "EMB";
  fs::create_directories(stick);
  DaemonProcess daemon(tmp.path(), "[embroidery]\nwidth_mm = 80\n[[device]]\nname = \"emb\"\n"
                                   "driver = \"file-drop\"\ndir = \"" + stick.string() + "\"\n");
  daemon.start();
  atelier::test::drop_file(atelier::test::test_image("HappyFish.jpg"),
                           daemon.incoming("embroidery") / "HappyFish.jpg");
  ASSERT_TRUE(daemon.wait_job_state("HappyFish.jpg", "completed")) << daemon.jobs().dump(2) << daemon.log();
  const json job = daemon.job_named("HappyFish.jpg");
  const std::string id = std::to_string(job["id"].get<int64_t>());
  const fs::path done = daemon.spool() / "done" / id;
  const json report = json::parse(read_file(done / "report.json"));

  // The machine's folder holds exactly the two files, whole, under the job's name.
  const fs::path dst = stick / (id + "-HappyFish.dst"), exp = stick / (id + "-HappyFish.exp");
  EXPECT_EQ(read_file(dst), read_file(done / "design.dst"));
  EXPECT_EQ(read_file(exp), read_file(done / "design.exp"));
  EXPECT_EQ(std::distance(fs::directory_iterator(stick), fs::directory_iterator()), 2);

  // The DST decodes: every record in range, the header counts the body, the design is 80 mm.
  const readers::DstFile f = readers::read_dst(read_file(dst));
  EXPECT_TRUE(f.errors.empty()) << f.errors.front();
  ASSERT_FALSE(f.records.empty());
  EXPECT_EQ(f.records.back().type, readers::Ev::end);
  long x = 0, y = 0, min_x = 0, max_x = 0, min_y = 0, max_y = 0;
  int colors = 0, stitches = 0;
  for (const readers::Rec& r : f.records) {
    EXPECT_LE(std::abs(r.dx), 121);
    EXPECT_LE(std::abs(r.dy), 121);
    x += r.dx;
    y += r.dy;
    min_x = std::min(min_x, x), max_x = std::max(max_x, x);
    min_y = std::min(min_y, y), max_y = std::max(max_y, y);
    colors += r.type == readers::Ev::color;
    stitches += r.type == readers::Ev::stitch;
  }
  EXPECT_EQ(readers::num(f.header.at("ST")), static_cast<long>(f.records.size()));
  EXPECT_EQ(readers::num(f.header.at("CO")), colors);
  EXPECT_EQ(readers::num(f.header.at("+X")), max_x);
  EXPECT_EQ(readers::num(f.header.at("-X")), -min_x);
  EXPECT_EQ(colors, report["color_changes"].get<int>());
  EXPECT_GE(stitches, report["stitches"].get<int>()) << "every planned stitch is in the file";
  EXPECT_GT(stitches, 1000) << "a filled 80 mm fish takes thousands of stitches";
  // Sewn at width_mm: within the 80 mm (plus pull compensation), and as the report says (the
  // trims' zero-sum jump wiggles folded away, as a machine cuts there rather than moves).
  long sewn_x = 0, sewn_min = 0, sewn_max = 0;
  for (const readers::Rec& r : readers::fold_dst_trims(f.records)) {
    sewn_x += r.dx;
    sewn_min = std::min(sewn_min, sewn_x), sewn_max = std::max(sewn_max, sewn_x);
  }
  const double width_mm = (sewn_max - sewn_min) / 10.0;
  EXPECT_LE(width_mm, 81.0);
  EXPECT_GT(width_mm, 40.0);
  EXPECT_NEAR(width_mm, report["extent_mm"]["width"].get<double>(), 0.2);

  // The preview, normal map and style labels are there at the working size.
  for (const char* png : {"preview.png", "normal.png", "regions.png"}) {
    const cv::Mat m = cv::imread((done / png).string());
    ASSERT_FALSE(m.empty()) << png;
    EXPECT_EQ(m.cols, report["work_size_px"][0].get<int>()) << png;
  }
  EXPECT_GT(report["regions"]["total"].get<int>(), 1);

  // The stick is pulled: the next job fails with the reason and keeps its design.
  fs::remove_all(stick);
  atelier::test::drop_file(atelier::test::test_image("pic1.png"), daemon.incoming("embroidery") / "pic1.png");
  ASSERT_TRUE(daemon.wait_job_state("pic1.png", "failed")) << daemon.jobs().dump(2);
  const json failed = daemon.job_named("pic1.png");
  EXPECT_NE(failed["reason"].get<std::string>().find("missing"), std::string::npos) << failed.dump();
  EXPECT_TRUE(fs::exists(daemon.spool() / "done" / std::to_string(failed["id"].get<int64_t>()) / "design.dst"));
}
