// SLIP framing (RFC 1055) as AYAB uses it: END 0xC0, ESC 0xDB, ESC_END 0xDC, ESC_ESC 0xDD.
// Pure; a SlipDecoder instance is not thread-safe.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

namespace atelier::ayab {

using Bytes = std::vector<uint8_t>;

// One packet framed as END payload-escaped END (a leading END flushes line noise).
Bytes slip_encode(const Bytes& payload);

// Streaming decoder: feed bytes as they arrive, collect whole packets. Empty packets are
// skipped; a packet longer than `max_packet` is dropped (line noise), as is a bad escape.
class SlipDecoder {
 public:
  explicit SlipDecoder(size_t max_packet = 256) : max_(max_packet) {}
  // Returns the packets completed by `data`, in order.
  std::vector<Bytes> feed(const uint8_t* data, size_t size);
  std::vector<Bytes> feed(const Bytes& data) { return feed(data.data(), data.size()); }

 private:
  size_t max_;
  Bytes current_;
  bool escaped_ = false;
  bool broken_ = false;
};

}  // namespace atelier::ayab
