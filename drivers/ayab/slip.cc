#include "drivers/ayab/slip.h"

namespace atelier::ayab {
namespace {
constexpr uint8_t kEnd = 0xC0, kEsc = 0xDB, kEscEnd = 0xDC, kEscEsc = 0xDD;
}

Bytes slip_encode(const Bytes& payload) {
  Bytes out;
  out.reserve(payload.size() + 4);
  out.push_back(kEnd);
  for (uint8_t b : payload) {
    if (b == kEnd) {
      out.push_back(kEsc);
      out.push_back(kEscEnd);
    } else if (b == kEsc) {
      out.push_back(kEsc);
      out.push_back(kEscEsc);
    } else {
      out.push_back(b);
    }
  }
  out.push_back(kEnd);
  return out;
}

std::vector<Bytes> SlipDecoder::feed(const uint8_t* data, size_t size) {
  std::vector<Bytes> packets;
  for (size_t i = 0; i < size; ++i) {
    const uint8_t b = data[i];
    if (b == kEnd) {
      if (!current_.empty() && !broken_ && !escaped_) packets.push_back(current_);
      current_.clear();
      escaped_ = broken_ = false;
      continue;
    }
    if (broken_) continue;
    if (escaped_) {
      escaped_ = false;
      if (b == kEscEnd) current_.push_back(kEnd);
      else if (b == kEscEsc) current_.push_back(kEsc);
      else broken_ = true;  // protocol violation: drop the packet
    } else if (b == kEsc) {
      escaped_ = true;
    } else {
      current_.push_back(b);
    }
    if (current_.size() > max_) broken_ = true;
  }
  return packets;
}

}  // namespace atelier::ayab
