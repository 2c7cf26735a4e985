#include "tools/knit_emu/packet_serial.h"

namespace atelier::knit_emu {
namespace {
constexpr uint8_t kEnd = 0xC0, kEsc = 0xDB, kEscEnd = 0xDC, kEscEsc = 0xDD;
constexpr uint8_t kInvalidAfterEsc = 0x01;
}  // namespace

std::vector<ayab::Bytes> PacketSerialDecoder::feed(const uint8_t* data, size_t size) {
  std::vector<ayab::Bytes> out;
  for (size_t i = 0; i < size && !hung_; ++i) {
    uint8_t b = data[i];
    if (poison_) {
      poison_ = false;
      raw_.push_back(kEsc);
      b = kInvalidAfterEsc;
    }
    if (b == kEnd) {
      end_of_packet(out);
      continue;
    }
    if (raw_.size() < kBufferBytes) raw_.push_back(b);
    else overflow_ = true;
  }
  return out;
}

void PacketSerialDecoder::end_of_packet(std::vector<ayab::Bytes>& out) {
  ayab::Bytes packet;
  bool bad_escape = false;
  for (size_t i = 0; i < raw_.size(); ++i) {
    if (raw_[i] != kEsc) {
      packet.push_back(raw_[i]);
      continue;
    }
    const bool last = i + 1 >= raw_.size();
    if (!last && raw_[i + 1] == kEscEnd) packet.push_back(kEnd);
    else if (!last && raw_[i + 1] == kEscEsc) packet.push_back(kEsc);
    else bad_escape = true;  // the library's decode loop never moves past this byte
    if (bad_escape) break;
    ++i;
  }
  const bool dropped = overflow_;
  raw_.clear();
  overflow_ = false;
  if (bad_escape) {
    hung_ = true;
    return;
  }
  if (!dropped && !packet.empty()) out.push_back(std::move(packet));
}

}  // namespace atelier::knit_emu
