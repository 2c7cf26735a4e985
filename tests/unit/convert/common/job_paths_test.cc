// What the converter may open for a job: inside the confinement folders, never through a
// symlink; as given when unconfined.
#include "convert/common/job_paths.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "convert/common/convert_error.h"

namespace {

namespace fs = std::filesystem;
using atelier::ConvertError;
using atelier::JobPaths;
using atelier::PathAccess;
using ::testing::HasSubstr;

class JobPathsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("atelier-job-paths-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(spool() / "work" / "7");
    fs::create_directories(dir_ / "private");
    std::ofstream(dir_ / "private" / "photo.png") << "private bytes";
    std::ofstream(spool() / "work" / "7" / "mine.png") << "job bytes";
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path spool() const { return dir_ / "spool"; }

  // The access of a key that a sidecar in work/7 set.
  PathAccess job_access() const {
    JobPaths paths({spool()});
    paths.mark_from_job("relax_mask", "face.png.toml", spool() / "work" / "7");
    return paths.access("relax_mask");
  }
  // Reads `p` as the job gave it (relative to the sidecar's folder).
  std::string error_of(const PathAccess& a, const fs::path& p) {
    try {
      a.read_text(a.resolve(p), 1 << 20);
    } catch (const ConvertError& e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
};

TEST_F(JobPathsTest, AFileInsideTheSpoolIsRead) {
  EXPECT_EQ(job_access().read_text(spool() / "work" / "7" / "mine.png", 100), "job bytes");
  EXPECT_EQ(job_access().read_text(job_access().resolve("mine.png"), 100), "job bytes");  // from the sidecar
}

TEST_F(JobPathsTest, AnAbsolutePathOutsideIsRefusedNamingTheSidecarAndKey) {
  const std::string e = error_of(job_access(), dir_ / "private" / "photo.png");
  EXPECT_THAT(e, HasSubstr("face.png.toml: key 'relax_mask': "));
  EXPECT_THAT(e, HasSubstr("photo.png: outside the spool"));
  EXPECT_THAT(e, ::testing::Not(HasSubstr("private bytes")));
}

TEST_F(JobPathsTest, ADotDotEscapeIsRefused) {
  EXPECT_THAT(error_of(job_access(), "../../../private/photo.png"), HasSubstr("outside the spool"));
}

TEST_F(JobPathsTest, ASymlinkInsideTheSpoolIsRefusedWhereverItPoints) {
  fs::create_symlink(dir_ / "private" / "photo.png", spool() / "work" / "7" / "out.png");
  fs::create_symlink(spool() / "work" / "7" / "mine.png", spool() / "work" / "7" / "in.png");
  fs::create_directory_symlink(dir_ / "private", spool() / "work" / "7" / "dir");
  EXPECT_THAT(error_of(job_access(), "out.png"), HasSubstr("symbolic link"));
  EXPECT_THAT(error_of(job_access(), "in.png"), HasSubstr("symbolic link"));
  EXPECT_THAT(error_of(job_access(), "dir/photo.png"), HasSubstr("symbolic link"));
}

TEST_F(JobPathsTest, UnconfinedAndTrustedKeysOpenAsGiven) {
  fs::create_symlink(dir_ / "private" / "photo.png", spool() / "work" / "7" / "out.png");
  JobPaths none;
  none.mark_from_job("relax_mask", "face.png.toml", spool() / "work" / "7");
  EXPECT_EQ(none.access("relax_mask").read_text(spool() / "work" / "7" / "out.png", 100), "private bytes");
  // Confined, but the key came from the daemon's config.
  JobPaths confined({spool()});
  EXPECT_EQ(confined.access("wood").read_text(dir_ / "private" / "photo.png", 100), "private bytes");
  // A companion file is job content: always confined.
  EXPECT_THAT(error_of(confined.companion("face.png"), spool() / "work" / "7" / "out.png"),
              HasSubstr("symbolic link"));
}

TEST_F(JobPathsTest, FoldersFifosAndLargeFilesAreRefusedByName) {
  EXPECT_THAT(error_of(job_access(), spool() / "work"), HasSubstr("work: is a folder, not a file"));
  ASSERT_EQ(::mkfifo((spool() / "work" / "7" / "pipe").c_str(), 0600), 0);
  EXPECT_THAT(error_of(job_access(), "pipe"), HasSubstr("pipe: not a regular file"));
  try {
    job_access().read_file(spool() / "work" / "7" / "mine.png", 3);
    ADD_FAILURE() << "no error";
  } catch (const ConvertError& e) {
    EXPECT_THAT(e.what(), HasSubstr("mine.png: file is 9 bytes, over the limit of 3 bytes"));
  }
}

TEST_F(JobPathsTest, ListingAFolderSkipsSymlinks) {
  fs::create_symlink(dir_ / "private" / "photo.png", spool() / "work" / "7" / "out.png");
  EXPECT_EQ(job_access().list_files(spool() / "work" / "7"), std::vector<std::string>{"mine.png"});
  EXPECT_THROW(job_access().list_files(dir_ / "private"), ConvertError);
}

}  // namespace
