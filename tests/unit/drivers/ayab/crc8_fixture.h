// Test helper shared by the CRC-8 and message tests: the AYAB CRC-8 of a string or of bytes.
#pragma once

#include <cstdint>
#include <string>

#include "drivers/ayab/crc8.h"
#include "drivers/ayab/messages.h"

namespace atelier::ayab::testing {

inline uint8_t crc_of(const std::string& s) { return crc8(reinterpret_cast<const uint8_t*>(s.data()), s.size()); }
inline uint8_t crc_of(const Bytes& b) { return crc8(b.data(), b.size()); }

}  // namespace atelier::ayab::testing
