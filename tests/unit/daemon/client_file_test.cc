// Files a control client hands the daemon: read from the descriptor the client opened, never
// by path for someone without the daemon's rights; regular files within the size limit only.
#include "daemon/client_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "tests/e2e/daemon_harness.h"
#include "tests/support/foreign_user.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;

class ClientFileTest : public ::testing::Test {
 protected:
  fs::path write(const std::string& name, const std::string& bytes) {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
    return dir_ / name;
  }
  static std::string read(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  test::TempDir tmp_;
  const fs::path& dir_ = tmp_.path();
};

TEST_F(ClientFileTest, APassedDescriptorIsCopiedWhateverThePathSays) {
  const fs::path real = write("real.png", "the bytes the client opened");
  ControlRequest request;
  request.verb = "submit";
  request.peer.uid = test::kNobody;
  request.files.emplace_back(::open(real.c_str(), O_RDONLY | O_CLOEXEC));
  UniqueFd fd = client_file(request, 0, "/etc/shadow", "atelierctl submit FILE");
  copy_client_file(fd.get(), "photo.png", dir_ / "copy", 1000);
  EXPECT_EQ(read(dir_ / "copy"), "the bytes the client opened");
}

TEST_F(ClientFileTest, ARawPathFromAForeignUidIsRefusedAndFromOurOwnIsOpened) {
  const fs::path secret = write("secret.png", "root:*:20228:0:99999:7:::");
  ::chmod(secret.c_str(), 0600);
  ControlRequest foreign;
  foreign.verb = "submit";
  foreign.peer.uid = test::kNobody;
  try {
    client_file(foreign, 0, secret.string(), "atelierctl submit FILE --kind K");
    FAIL() << "a foreign uid's raw path was opened";
  } catch (const ControlError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("submit passes the open file; use atelierctl submit FILE --kind K"), std::string::npos)
        << what;
    EXPECT_EQ(what.find("root:*"), std::string::npos);
  }
  ControlRequest own;
  own.verb = "submit";
  own.peer.uid = ::geteuid();
  UniqueFd fd = client_file(own, 0, secret.string(), "atelierctl submit FILE");
  EXPECT_TRUE(fd.valid());
}

TEST_F(ClientFileTest, NonRegularAndOversizedFilesAreRefusedAndLeaveNothing) {
  int pipe_fds[2];
  ASSERT_EQ(::pipe(pipe_fds), 0);
  EXPECT_THROW(copy_client_file(pipe_fds[0], "fifo.png", dir_ / "copy", 1000), ControlError);
  ::close(pipe_fds[0]);
  ::close(pipe_fds[1]);
  const fs::path big = write("big.png", std::string(2000, 'x'));
  UniqueFd fd(::open(big.c_str(), O_RDONLY | O_CLOEXEC));
  try {
    copy_client_file(fd.get(), "big.png", dir_ / "copy", 1000);
    FAIL() << "an oversized file was copied";
  } catch (const ControlError& e) {
    EXPECT_NE(std::string(e.what()).find("big.png: 2000 bytes is larger than the limit of 1000 bytes"),
              std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(dir_ / "copy"));
}

TEST_F(ClientFileTest, TheNameIsTheLastComponentAndMustBeOne) {
  EXPECT_EQ(client_file_name("/home/ann/cat.png"), "cat.png");
  EXPECT_THROW(client_file_name("/home/ann/.."), ControlError);
  EXPECT_THROW(client_file_name("/"), ControlError);
  EXPECT_THROW(client_file_name(""), ControlError);
}

}  // namespace
}  // namespace atelier
