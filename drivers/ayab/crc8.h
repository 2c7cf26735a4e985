// CRC-8 Dallas/Maxim as AYAB uses it: reflected polynomial 0x8C, initial value 0, no final
// XOR. Check value: crc8("123456789") == 0xA1. Pure, thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>

namespace atelier::ayab {

uint8_t crc8(const uint8_t* data, size_t size);

}  // namespace atelier::ayab
