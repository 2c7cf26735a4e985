// The conversion memory budget (convert/common/memory_budget.h): an allocation beyond it is
// reported as "NAME: needs more than N MB (limits.job_memory_mb)".
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <new>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <vector>

#include "convert/common/memory_budget.h"

namespace atelier {
namespace {

// The address space in use now, in MB.
uint64_t vm_mb() {
  std::ifstream statm("/proc/self/statm");
  uint64_t pages = 0;
  statm >> pages;
  return pages * static_cast<uint64_t>(::sysconf(_SC_PAGESIZE)) >> 20;
}

TEST(MemoryBudget, OutOfMemoryErrorsAreRecognised) {
  EXPECT_TRUE(is_out_of_memory(std::bad_alloc()));
  EXPECT_TRUE(is_out_of_memory(cv::Exception(cv::Error::StsNoMem, "Failed to allocate 1 bytes", "f", "x.cc", 1)));
  EXPECT_FALSE(is_out_of_memory(std::runtime_error("x.png: not an image")));
  EXPECT_EQ(memory_exceeded_reason("big.png", 2048), "big.png: needs more than 2048 MB (limits.job_memory_mb)");
}

TEST(MemoryBudgetDeathTest, AnAllocationBeyondTheBudgetFailsAndIsReported) {
  // In a child process: the budget is what is in use now plus 64 MB; 1 GB is then refused,
  // by the C++ allocator and by OpenCV alike, instead of being granted (the limit was 8 GB).
  EXPECT_EXIT(
      {
        const uint64_t budget = vm_mb() + 64;
        apply_memory_budget(budget, "big.png");
        int refused = 0;
        try {
          std::vector<char> v(1ull << 30, 1);
          std::fprintf(stderr, "granted %c\n", v.back());
        } catch (const std::exception& e) {
          refused += is_out_of_memory(e);
        }
        try {
          cv::Mat m(32768, 32768, CV_8UC1);
          std::fprintf(stderr, "granted %d\n", m.rows);
        } catch (const std::exception& e) {
          refused += is_out_of_memory(e);
        }
        std::fprintf(stderr, "%s refused %d\n", memory_exceeded_reason("big.png", budget).c_str(), refused);
        std::_Exit(refused == 2 ? 3 : 4);
      },
      ::testing::ExitedWithCode(3), "big.png: needs more than [0-9]+ MB \\(limits.job_memory_mb\\) refused 2");
}

}  // namespace
}  // namespace atelier
