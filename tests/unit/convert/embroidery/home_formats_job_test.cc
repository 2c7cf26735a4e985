// convert() for kind embroidery writes design.pes and design.jef beside design.dst and
// design.exp (issue 21): on a real image, read back by the tests' own readers, the home
// machines' files sew what the DST sews (same stitches, trims, colour changes, end point) in
// the threads nearest the design's colours, and report.json lists them.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "convert/convert.h"
#include "convert/embroidery/thread_palettes.h"
#include "tests/support/pes_jef_readers.h"
#include "tests/support/stitch_file_readers.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using namespace atelier::embroidery::test;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct Tally {
  int stitches = 0, trims = 0, colors = 0, ends = 0;
  long x = 0, y = 0;
};
Tally tally(const std::vector<Rec>& recs) {
  Tally t;
  for (const Rec& r : recs) {
    t.stitches += r.type == Ev::stitch;
    t.trims += r.type == Ev::trim;
    t.colors += r.type == Ev::color;
    t.ends += r.type == Ev::end;
    t.x += r.dx, t.y += r.dy;
  }
  return t;
}

TEST(EmbroideryHomeFormats, AConvertedImageHasPesAndJefThatSewWhatItsDstSews) {
  const fs::path out = fs::temp_directory_path() / ("atelier-home-formats-" + std::to_string(::getpid()));
  fs::remove_all(out);
  ConvertRequest req;
  req.kind = "embroidery";
  req.input = fs::path(ATELIER_TEST_DATA) / "HappyFish.jpg";
  req.params = toml::parse("width_mm = 60\n", std::string_view{"test.toml"});
  req.params_source = "test.toml";
  req.output_dir = out;
  const ConvertResult r = convert(req);
  EXPECT_EQ(r.report["files"], (nlohmann::json{"design.dst", "design.exp", "design.pes", "design.jef"}));

  const DstFile dst = read_dst(slurp(out / "design.dst"));
  const PesFile pes = read_pes(slurp(out / "design.pes"));
  const JefFile jef = read_jef(slurp(out / "design.jef"));
  ASSERT_TRUE(dst.errors.empty()) << dst.errors.front();
  ASSERT_TRUE(pes.errors.empty()) << pes.errors.front();
  ASSERT_TRUE(jef.errors.empty()) << jef.errors.front();
  const Tally d = tally(fold_dst_trims(dst.records)), p = tally(y_up(pes.records)), j = tally(jef.records);
  EXPECT_EQ(d.stitches, r.report["stitches"].get<int>());  // no stitch over 12.1 mm: none split
  EXPECT_EQ(p.stitches, d.stitches);
  EXPECT_EQ(j.stitches, d.stitches);
  EXPECT_EQ(p.trims, r.report["trims"].get<int>());
  EXPECT_EQ(j.trims, r.report["trims"].get<int>());
  EXPECT_EQ(p.colors, r.report["color_changes"].get<int>());
  EXPECT_EQ(j.colors, r.report["color_changes"].get<int>());
  EXPECT_EQ(p.ends, 1);
  EXPECT_EQ(j.ends, 1);
  EXPECT_EQ(p.x, d.x);
  EXPECT_EQ(p.y, d.y);
  EXPECT_EQ(j.x, d.x);
  EXPECT_EQ(j.y, d.y);
  EXPECT_EQ(pes.label.substr(0, 9), "HappyFish");

  // One thread per colour block, the nearest of each maker's table (distinct kept distinct).
  std::vector<std::uint32_t> colors;
  for (const auto& t : r.report["threads"])
    colors.push_back(static_cast<std::uint32_t>(std::stoul(t["rgb"].get<std::string>().substr(1), nullptr, 16)));
  ASSERT_EQ(colors.size(), static_cast<size_t>(d.colors + 1));
  EXPECT_EQ(pes.threads, embroidery::assign_threads(embroidery::pec_threads(), colors));
  std::vector<long> want_jef;
  for (int t : embroidery::assign_threads(embroidery::jef_threads(), colors)) want_jef.push_back(t);
  EXPECT_EQ(jef.threads, want_jef);
  EXPECT_EQ(pes.thumbs.size(), colors.size() + 1);
  fs::remove_all(out);
}

}  // namespace
}  // namespace atelier
