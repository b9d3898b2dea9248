#pragma once
/// CRC-32 (IEEE 802.3: reflected polynomial 0xEDB88320, initial value and final XOR 0xFFFFFFFF),
/// bitwise: a stored record is read once at start-up and written rarely, so no table is spent
/// on speed. Check value: crc32("123456789") = 0xCBF43926.
#include <cstdint>
#include <span>

namespace imd::hal {

constexpr uint32_t crc32(std::span<const uint8_t> bytes, uint32_t crc = 0) noexcept {
  crc = ~crc;
  for (const uint8_t b : bytes) {
    crc ^= b;
    for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

}  // namespace imd::hal
