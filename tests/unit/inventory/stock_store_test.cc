// The stock of used wood on disk (inventory/stock_store.h): stock.json round trip,
// corrupt files named, and the lock that serialises conversions.
#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <filesystem>
#include <fstream>
#include <future>
#include <nlohmann/json.hpp>
#include <thread>

#include "inventory/stock_store.h"
#include "tests/support/thread_state.h"

namespace atelier {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

class StockStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("atelier-stock-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void write(const std::string& text) {
    fs::create_directories(dir_);
    std::ofstream(dir_ / "stock.json") << text;
  }
  fs::path dir_;
};

TEST_F(StockStoreTest, MissingFileIsAnEmptyStock) {
  EXPECT_TRUE(load_stock(dir_).used.empty());
  EXPECT_FALSE(fs::exists(dir_));  // reading creates nothing
}

TEST_F(StockStoreTest, RoundTripKeepsJobsPiecesAndPolygons) {
  parquetry::Stock s;
  s.used["maple"].push_back({"12", 3, {{0, 0}, {14.125, 0}, {14.125, 14}, {0, 14}}});
  s.used["maple"].push_back({"13", 1, {{20, 20}, {30, 20}, {25, 31.5}}});
  s.used["cherry"].push_back({"", 7, {{1, 2}, {3, 4}, {5, 1}}});
  save_stock(dir_, s);
  ASSERT_TRUE(fs::exists(dir_ / "stock.json"));
  EXPECT_FALSE(fs::exists(dir_ / "stock.json.tmp"));

  nlohmann::json j = nlohmann::json::parse(std::ifstream(dir_ / "stock.json"));
  EXPECT_EQ(j["version"], 1);
  EXPECT_EQ(j["sheets"]["maple"][0]["job"], "12");
  EXPECT_EQ(j["sheets"]["maple"][0]["piece"], 3);
  EXPECT_DOUBLE_EQ(j["sheets"]["maple"][0]["polygon"][1][0].get<double>(), 14.125);

  parquetry::Stock back = load_stock(dir_);
  ASSERT_EQ(back.used.size(), 2u);
  ASSERT_EQ(back.used["maple"].size(), 2u);
  EXPECT_EQ(back.used["maple"][1].job, "13");
  EXPECT_EQ(back.used["maple"][1].piece, 1);
  ASSERT_EQ(back.used["maple"][1].polygon_mm.size(), 3u);
  EXPECT_DOUBLE_EQ(back.used["maple"][1].polygon_mm[2].y, 31.5);
  EXPECT_EQ(back.used["cherry"][0].piece, 7);
}

TEST_F(StockStoreTest, CorruptFilesAreNamed) {
  for (const char* text : {"{not json", "[]", "{\"version\": 2, \"sheets\": {}}",
                           "{\"version\": 1}", "{\"version\": 1, \"sheets\": {\"a\": [{\"job\": \"1\"}]}}",
                           "{\"version\": 1, \"sheets\": {\"a\": [{\"polygon\": [[0, 0], [1]]}]}}",
                           "{\"version\": 1, \"sheets\": {\"a\": [{\"polygon\": [[0, 0], [1, 1]]}]}}"}) {
    write(text);
    try {
      load_stock(dir_);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const ConvertError& e) {
      EXPECT_THAT(e.what(), HasSubstr("stock.json: corrupt stock file")) << text;
    }
  }
}

TEST_F(StockStoreTest, LockExcludesASecondHolderUntilReleased) {
  std::atomic<bool> second_has_it{false};
  std::promise<pid_t> second_thread;
  std::thread other;
  {
    StockLock first(dir_);
    EXPECT_TRUE(fs::exists(dir_ / "stock.lock"));
    // Nobody else gets the lock while we hold it: a try on the file is refused.
    const int probe = ::open((dir_ / "stock.lock").c_str(), O_RDWR | O_CLOEXEC);
    ASSERT_GE(probe, 0);
    const int tried = ::flock(probe, LOCK_EX | LOCK_NB);
    const int why = errno;
    ::close(probe);
    EXPECT_EQ(tried, -1);
    EXPECT_EQ(why, EWOULDBLOCK);
    other = std::thread([&] {
      second_thread.set_value(test::this_thread_id());
      StockLock second(dir_);
      second_has_it = true;
    });
    // A second holder waits for it: once it is blocked in flock(2) it still must not have it.
    // (No timing assertion: whatever the scheduling, it cannot get in while we hold the lock.)
    test::wait_until_in_syscall(second_thread.get_future().get(), {SYS_flock});
    EXPECT_FALSE(second_has_it.load());
  }
  other.join();
  EXPECT_TRUE(second_has_it.load());
}

}  // namespace
}  // namespace atelier
