// An input held in an anonymous memory file (memfd), for entry points that read a path:
// path() is /proc/self/fd/N. No disk I/O, nothing left behind. Owns the descriptor.
// Throws std::runtime_error when memfd_create or the write fails.
#pragma once

#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace atelier::fuzz {

class MemoryFile {
 public:
  MemoryFile(const uint8_t* data, size_t size) : fd_(::memfd_create("atelier-fuzz", MFD_CLOEXEC)) {
    if (fd_ < 0) throw std::runtime_error("memfd_create failed");
    for (size_t off = 0; off < size;) {
      ssize_t n = ::write(fd_, data + off, size - off);
      if (n <= 0) {
        ::close(fd_);
        throw std::runtime_error("memfd write failed");
      }
      off += static_cast<size_t>(n);
    }
  }
  ~MemoryFile() { ::close(fd_); }
  MemoryFile(const MemoryFile&) = delete;
  MemoryFile& operator=(const MemoryFile&) = delete;

  std::filesystem::path path() const { return "/proc/self/fd/" + std::to_string(fd_); }

 private:
  int fd_;
};

}  // namespace atelier::fuzz
