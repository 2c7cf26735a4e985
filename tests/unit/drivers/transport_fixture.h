// Reading and writing strings over any Transport, for the memory and serial transport tests.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

#include "drivers/transport.h"

namespace atelier::test {

// Up to `want` bytes, each read waiting at most 2 s (of the transport's clock); fewer when a
// read times out.
inline std::string read_all(Transport& t, size_t want) {
  std::string out;
  uint8_t buf[64];
  while (out.size() < want) {
    const size_t n = t.read(buf, sizeof buf, std::chrono::milliseconds(2000));
    if (n == 0) break;
    out.append(reinterpret_cast<char*>(buf), n);
  }
  return out;
}

inline void write_str(Transport& t, const std::string& s) {
  t.write(reinterpret_cast<const uint8_t*>(s.data()), s.size());
}

}  // namespace atelier::test
