#include "convert/common/memory_budget.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <new>
#include <opencv2/core.hpp>
#include <stdexcept>

namespace atelier {
namespace {

constexpr uint64_t kNearLimitBytes = 64ull << 20;

// Written once by apply_memory_budget, read by the handler.
uint64_t g_limit_bytes = 0;
char g_message[512];
size_t g_message_size = 0;
char g_alt_stack[64 * 1024];

// Address-space size in bytes from /proc/self/statm (first field, in pages); 0 if unknown.
// Only async-signal-safe calls.
uint64_t vm_bytes() {
  int fd = ::open("/proc/self/statm", O_RDONLY | O_CLOEXEC);
  if (fd < 0) return 0;
  char buf[64];
  ssize_t n = ::read(fd, buf, sizeof buf - 1);
  ::close(fd);
  if (n <= 0) return 0;
  uint64_t pages = 0;
  for (ssize_t i = 0; i < n && buf[i] >= '0' && buf[i] <= '9'; ++i) pages = pages * 10 + static_cast<uint64_t>(buf[i] - '0');
  return pages * static_cast<uint64_t>(::sysconf(_SC_PAGESIZE));
}

void on_segv(int sig) {
  if (vm_bytes() + kNearLimitBytes >= g_limit_bytes) {
    ssize_t ignored = ::write(2, g_message, g_message_size);
    (void)ignored;
    _exit(1);
  }
  // Not the budget: die of the signal, as without the handler.
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

}  // namespace

std::string memory_exceeded_reason(const std::string& input_name, uint64_t mb) {
  return input_name + ": needs more than " + std::to_string(mb) + " MB (limits.job_memory_mb)";
}

void apply_memory_budget(uint64_t mb, const std::string& input_name) {
  g_limit_bytes = mb << 20;
  const std::string text = "error: " + memory_exceeded_reason(input_name, mb) + "\n";
  g_message_size = std::min(text.size(), sizeof g_message);
  std::memcpy(g_message, text.data(), g_message_size);

  stack_t alt{};
  alt.ss_sp = g_alt_stack;
  alt.ss_size = sizeof g_alt_stack;
  ::sigaltstack(&alt, nullptr);  // a stack overflow has no stack left for the handler
  struct sigaction sa{};
  sa.sa_handler = on_segv;
  sa.sa_flags = SA_ONSTACK;
  sigemptyset(&sa.sa_mask);
  ::sigaction(SIGSEGV, &sa, nullptr);

  struct rlimit lim = {static_cast<rlim_t>(g_limit_bytes), static_cast<rlim_t>(g_limit_bytes)};
  if (::setrlimit(RLIMIT_AS, &lim) != 0)
    throw std::runtime_error("cannot set the memory limit of " + std::to_string(mb) + " MB: " + std::strerror(errno));
}

bool is_out_of_memory(const std::exception& e) {
  if (dynamic_cast<const std::bad_alloc*>(&e)) return true;
  if (const auto* cv_error = dynamic_cast<const cv::Exception*>(&e)) {
    if (cv_error->code == cv::Error::StsNoMem) return true;
  }
  const char* what = e.what();
  return std::strstr(what, "Insufficient memory") || std::strstr(what, "Failed to allocate");
}

}  // namespace atelier
