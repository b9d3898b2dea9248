#pragma once
/// End-to-end protection of command frames, in the style of AUTOSAR E2E profile 1: byte 0 holds
/// a CRC-8 (SAE J1850: polynomial 0x1D, initial value 0xFF, final XOR 0xFF) over the data id
/// (the 11-bit CAN identifier, low byte first) and bytes 1..length-1; the low nibble of byte 1
/// holds a 4-bit alive counter. Including the identifier makes a frame that reached the wrong
/// node or message fail its CRC.
#include <cstdint>

#include "firmware/protocol/can_signal.hpp"

namespace imd::firmware::protocol {

/// CRC-8 SAE J1850, bitwise (no table: 16 bytes at most per frame).
constexpr uint8_t crc8_sae_j1850(const uint8_t* bytes, int count, uint8_t crc = 0xFF) noexcept {
  for (int i = 0; i < count; ++i) {
    crc ^= bytes[i];
    for (int bit = 0; bit < 8; ++bit) {
      crc = (crc & 0x80) != 0 ? static_cast<uint8_t>((crc << 1) ^ 0x1D)
                              : static_cast<uint8_t>(crc << 1);
    }
  }
  return crc;
}

/// The CRC of a command frame: over the data id and bytes 1..length-1 (byte 0 is the CRC).
constexpr uint8_t e2e_crc(uint16_t can_id, const Payload& data, uint8_t length) noexcept {
  uint8_t buffer[2 + 7] = {static_cast<uint8_t>(can_id & 0xFF), static_cast<uint8_t>(can_id >> 8)};
  int n = 2;
  for (int i = 1; i < length && i < 8; ++i) buffer[n++] = data[i];
  return static_cast<uint8_t>(crc8_sae_j1850(buffer, n) ^ 0xFF);
}

constexpr uint8_t e2e_counter(const Payload& data) noexcept {
  return data[1] & 0x0F;
}

/// Fills in the counter and the CRC of a command frame whose payload is already written.
constexpr void e2e_protect(uint16_t can_id, Payload& data, uint8_t length,
                           uint8_t counter) noexcept {
  data[1] = static_cast<uint8_t>((data[1] & 0xF0) | (counter & 0x0F));
  data[0] = e2e_crc(can_id, data, length);
}

}  // namespace imd::firmware::protocol
