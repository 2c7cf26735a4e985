// The web server serves a job's own outputs and nothing else: no traversal, no symlink out of
// the spool, no FIFO to hang on.
#include "daemon/web/job_files.h"

#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
#include <gtest/gtest.h>

namespace atelier::web {
namespace {

namespace fs = std::filesystem;

class JobFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("atelier-jobfiles-" + std::to_string(::getpid()) + "-" +
                                         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    spool_ = root_ / "spool";
    fs::create_directories(spool_ / "done" / "12");
    fs::create_directories(spool_ / "failed" / "13");
    std::ofstream(spool_ / "done" / "12" / "preview.png") << "PNGDATA";
    std::ofstream(spool_ / "failed" / "13" / "reason.txt") << "bad";
    std::ofstream(root_ / "secret.txt") << "SECRET";
  }
  void TearDown() override { fs::remove_all(root_); }
  std::string read(std::optional<OpenedFile>& f) {
    std::string s(f->size, '\0');
    EXPECT_EQ(::pread(f->fd.get(), s.data(), s.size(), 0), static_cast<ssize_t>(s.size()));
    return s;
  }
  fs::path root_, spool_;
};

TEST_F(JobFiles, OpensAnOutputOfADoneOrFailedJob) {
  auto f = open_job_file(spool_, spool_ / "done" / "12", "preview.png");
  ASSERT_TRUE(f);
  EXPECT_EQ(f->size, 7u);
  EXPECT_EQ(read(f), "PNGDATA");
  EXPECT_TRUE(open_job_file(spool_, spool_ / "failed" / "13", "reason.txt"));
  EXPECT_FALSE(open_job_file(spool_, spool_ / "done" / "12", "missing.png"));
}

TEST_F(JobFiles, RefusesNamesThatLeaveTheFolder) {
  const fs::path dir = spool_ / "done" / "12";
  for (const std::string& name : std::vector<std::string>{"", ".", "..", "../13/x", "../../../secret.txt",
                                                        "/etc/passwd", "a/b", std::string("preview.png\0x", 13)})
    EXPECT_FALSE(open_job_file(spool_, dir, name)) << name;
}

TEST_F(JobFiles, RefusesOutputFoldersOutsideDoneAndFailed) {
  fs::create_directories(spool_ / "work" / "14");
  std::ofstream(spool_ / "work" / "14" / "in.png") << "x";
  EXPECT_FALSE(open_job_file(spool_, spool_ / "work" / "14", "in.png"));
  EXPECT_FALSE(open_job_file(spool_, root_, "secret.txt"));
  EXPECT_FALSE(open_job_file(spool_, spool_ / "done" / ".." / ".." , "secret.txt"));
  EXPECT_FALSE(open_job_file(spool_, spool_ / "done" / "12" / "..", "12"));
  EXPECT_FALSE(open_job_file(spool_, spool_ / "done" / "abc", "x"));
}

TEST_F(JobFiles, FollowsNoSymlinkAtAnyLevel) {
  fs::create_symlink(root_ / "secret.txt", spool_ / "done" / "12" / "link.png");
  EXPECT_FALSE(open_job_file(spool_, spool_ / "done" / "12", "link.png"));
  fs::create_directories(root_ / "elsewhere");
  std::ofstream(root_ / "elsewhere" / "preview.png") << "OUTSIDE";
  fs::create_directory_symlink(root_ / "elsewhere", spool_ / "done" / "15");
  EXPECT_FALSE(open_job_file(spool_, spool_ / "done" / "15", "preview.png"));
  fs::create_directories(root_ / "fakedone" / "16");
  std::ofstream(root_ / "fakedone" / "16" / "preview.png") << "OUTSIDE";
  fs::rename(spool_ / "failed", root_ / "oldfailed");
  fs::create_directory_symlink(root_ / "fakedone", spool_ / "failed");
  EXPECT_FALSE(open_job_file(spool_, spool_ / "failed" / "16", "preview.png"));
}

TEST_F(JobFiles, RefusesWhatIsNotARegularFileWithoutBlocking) {
  ASSERT_EQ(::mkfifo((spool_ / "done" / "12" / "pipe.png").c_str(), 0600), 0);
  EXPECT_FALSE(open_job_file(spool_, spool_ / "done" / "12", "pipe.png"));  // returns, does not hang
  fs::create_directory(spool_ / "done" / "12" / "sub");
  EXPECT_FALSE(open_job_file(spool_, spool_ / "done" / "12", "sub"));
}

TEST(JobFileTypes, PicturesAndTextInlineEverythingElseDownloaded) {
  EXPECT_EQ(content_type_for("preview.png"), "image/png");
  EXPECT_EQ(content_type_for("chart.SVG"), "image/svg+xml");
  EXPECT_EQ(content_type_for("chart.pdf"), "application/pdf");
  EXPECT_EQ(content_type_for("design.dst"), "application/octet-stream");
  EXPECT_TRUE(shown_inline("preview.png"));
  EXPECT_TRUE(shown_inline("report.json"));
  EXPECT_TRUE(shown_inline("job.gcode"));
  EXPECT_FALSE(shown_inline("design.pes"));
  EXPECT_FALSE(shown_inline("chart.pdf"));
}

TEST(JobFileTypes, PreviewsInTheKindsOrderAmongTheOutputs) {
  EXPECT_EQ(preview_files("knit", {"chart.pdf", "pattern.png", "preview.png", "report.json"}),
            (std::vector<std::string>{"preview.png", "pattern.png"}));
  EXPECT_EQ(preview_files("embroidery", {"design.dst", "preview.png", "stitches.png", "regions.png"}),
            (std::vector<std::string>{"preview.png", "stitches.png", "regions.png"}));
  EXPECT_EQ(preview_files("parquetry", {"assembly.svg", "preview.png"}),
            (std::vector<std::string>{"preview.png", "assembly.svg"}));
  EXPECT_TRUE(preview_files("knit", {"reason.txt", "cat.jpg"}).empty());  // a failed job
  EXPECT_TRUE(preview_files("nonsense", {"preview.png"}).empty());
}

}  // namespace
}  // namespace atelier::web
