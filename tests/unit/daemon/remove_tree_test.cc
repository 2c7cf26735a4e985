// Removing a folder tree without following symlinks (daemon/remove_tree.h).
#include "daemon/remove_tree.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "tests/e2e/daemon_harness.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using test::TempDir;
using test::write_file;

class RemoveTree : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::create_directories(tmp_.path() / "spool");
    fs::create_directories(tmp_.path() / "outside" / "dir");
    write_file(tmp_.path() / "outside" / "precious.txt", "keep me");
    write_file(tmp_.path() / "outside" / "dir" / "inner.txt", "keep me too");
    fd_ = ::open((tmp_.path() / "spool").c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    ASSERT_GE(fd_, 0);
  }
  void TearDown() override { ::close(fd_); }
  fs::path spool() const { return tmp_.path() / "spool"; }
  fs::path outside() const { return tmp_.path() / "outside"; }

  TempDir tmp_;
  int fd_ = -1;
};

TEST_F(RemoveTree, RemovesAFolderWithNestedFoldersAndFiles) {
  fs::create_directories(spool() / "7" / "a" / "b");
  write_file(spool() / "7" / "report.json", "{}");
  write_file(spool() / "7" / "a" / "b" / "deep.txt", "x");
  std::string failed;
  EXPECT_FALSE(remove_tree_at(fd_, "7", failed));
  EXPECT_FALSE(fs::exists(spool() / "7"));
  EXPECT_FALSE(remove_tree_at(fd_, "7", failed)) << "already gone is success";
}

TEST_F(RemoveTree, ASymlinkInsideIsRemovedAndWhatItPointsToIsNot) {
  fs::create_directories(spool() / "7" / "sub");
  fs::create_directory_symlink(outside() / "dir", spool() / "7" / "to-dir");
  fs::create_symlink(outside() / "precious.txt", spool() / "7" / "sub" / "to-file");
  std::string failed;
  EXPECT_FALSE(remove_tree_at(fd_, "7", failed)) << failed;
  EXPECT_FALSE(fs::exists(fs::symlink_status(spool() / "7")));
  EXPECT_EQ(test::read_file(outside() / "precious.txt"), "keep me");
  EXPECT_EQ(test::read_file(outside() / "dir" / "inner.txt"), "keep me too");
}

TEST_F(RemoveTree, TheFolderItselfBeingASymlinkRemovesOnlyTheLink) {
  fs::create_directory_symlink(outside(), spool() / "7");
  std::string failed;
  EXPECT_FALSE(remove_tree_at(fd_, "7", failed));
  EXPECT_FALSE(fs::exists(fs::symlink_status(spool() / "7")));
  EXPECT_EQ(test::read_file(outside() / "precious.txt"), "keep me");
}

TEST_F(RemoveTree, ANameWithASlashOrDotsIsRefused) {
  std::string failed;
  for (const char* name : {"", ".", "..", "../outside", "a/b"})
    EXPECT_EQ(remove_tree_at(fd_, name, failed), std::errc::invalid_argument) << name;
  EXPECT_TRUE(fs::exists(outside() / "precious.txt"));
}

TEST_F(RemoveTree, ATreeDeeperThanTheLimitIsLeftAndNamed) {
  fs::path p = spool() / "7";
  for (int i = 0; i <= kMaxRemoveDepth + 1; ++i) p /= "d";
  fs::create_directories(p);
  std::string failed;
  EXPECT_EQ(remove_tree_at(fd_, "7", failed), std::errc::too_many_symbolic_link_levels);
  EXPECT_EQ(failed.rfind("7/d/d/", 0), 0u) << failed;
  EXPECT_TRUE(fs::exists(spool() / "7"));
}

}  // namespace
}  // namespace atelier
