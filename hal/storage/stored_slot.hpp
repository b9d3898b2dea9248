#pragma once
/// The frame a stored record is kept in, the same in every backend (flash page, file):
///
///   offset 0   magic     u32  "IMDS"
///          4   sequence  u32  +1 per save; the newest valid copy wins
///          8   length    u16  bytes of data
///         10   ~length   u16  its complement (a torn header cannot pass as a short record)
///         12   data      length bytes, then 0xFF up to a multiple of 8
///          n   crc32     u32  over bytes 0..n-1
///        n+4   reserved  u32  0xFFFFFFFF
///        n+8   commit    u32  0x00C0FFEE, written last and on its own
///
/// Everything is little-endian. The commit word goes in a separate write after everything
/// else, so a write cut off anywhere leaves no commit word (flash reads 0xFF where nothing was
/// written): a copy without it is not loaded. The CRC catches what the commit word cannot (a
/// page worn or disturbed after the write). Header-only: it runs on the MCU and on Linux.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "hal/storage/crc32.hpp"

namespace imd::hal {

inline constexpr uint32_t kSlotMagic = 0x53444D49u;   // "IMDS" read as little-endian bytes
inline constexpr uint32_t kSlotCommit = 0x00C0FFEEu;  // has no 0xFF byte
inline constexpr std::size_t kSlotHeaderBytes = 12;
inline constexpr std::size_t kSlotAlign = 8;          // the flash's programming unit
inline constexpr std::size_t kSlotTrailerBytes = 8;   // crc32 + reserved
inline constexpr std::size_t kSlotCommitBytes = 8;    // commit word + reserved, its own unit

constexpr std::size_t slot_body_bytes(std::size_t data_bytes) noexcept {
  const std::size_t unaligned = kSlotHeaderBytes + data_bytes;
  return (unaligned + kSlotAlign - 1) / kSlotAlign * kSlotAlign + kSlotTrailerBytes;
}
/// Everything a copy occupies: the body and, after it, the commit unit.
constexpr std::size_t slot_bytes(std::size_t data_bytes) noexcept {
  return slot_body_bytes(data_bytes) + kSlotCommitBytes;
}

namespace detail {
constexpr void put_u32(uint8_t* p, uint32_t v) noexcept {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
constexpr void put_u16(uint8_t* p, uint16_t v) noexcept {
  p[0] = static_cast<uint8_t>(v);
  p[1] = static_cast<uint8_t>(v >> 8);
}
constexpr uint32_t get_u32(const uint8_t* p) noexcept {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}
constexpr uint16_t get_u16(const uint8_t* p) noexcept {
  return static_cast<uint16_t>(p[0] | p[1] << 8);
}
}  // namespace detail

/// Writes the body of a copy (everything but the commit unit) into `out`, which must hold
/// slot_body_bytes(data.size()). Returns the bytes written.
constexpr std::size_t encode_slot_body(uint32_t sequence, std::span<const uint8_t> data,
                                       std::span<uint8_t> out) noexcept {
  const std::size_t n = slot_body_bytes(data.size());
  if (out.size() < n || data.size() > 0xFFFF) return 0;
  uint8_t* p = out.data();
  detail::put_u32(p, kSlotMagic);
  detail::put_u32(p + 4, sequence);
  detail::put_u16(p + 8, static_cast<uint16_t>(data.size()));
  detail::put_u16(p + 10, static_cast<uint16_t>(~data.size()));
  for (std::size_t i = 0; i < data.size(); ++i) p[kSlotHeaderBytes + i] = data[i];
  const std::size_t crc_at = n - kSlotTrailerBytes;
  for (std::size_t i = kSlotHeaderBytes + data.size(); i < crc_at; ++i) p[i] = 0xFF;
  detail::put_u32(p + crc_at, crc32(std::span<const uint8_t>(p, crc_at)));
  detail::put_u32(p + crc_at + 4, 0xFFFFFFFFu);
  return n;
}

/// The commit unit, written after the body.
constexpr std::array<uint8_t, kSlotCommitBytes> slot_commit_unit() noexcept {
  std::array<uint8_t, kSlotCommitBytes> unit{};
  detail::put_u32(unit.data(), kSlotCommit);
  detail::put_u32(unit.data() + 4, 0xFFFFFFFFu);
  return unit;
}

/// A copy that passed every check.
struct SlotView {
  uint32_t sequence;
  std::span<const uint8_t> data;
};

/// The copy at the start of `bytes`, if it is whole: magic, length and its complement, the
/// CRC and the commit word.
constexpr std::optional<SlotView> decode_slot(std::span<const uint8_t> bytes) noexcept {
  if (bytes.size() < slot_bytes(0)) return std::nullopt;
  const uint8_t* p = bytes.data();
  if (detail::get_u32(p) != kSlotMagic) return std::nullopt;
  const uint16_t length = detail::get_u16(p + 8);
  if (static_cast<uint16_t>(~length) != detail::get_u16(p + 10)) return std::nullopt;
  const std::size_t body = slot_body_bytes(length);
  if (bytes.size() < body + kSlotCommitBytes) return std::nullopt;
  if (detail::get_u32(p + body) != kSlotCommit) return std::nullopt;
  const std::size_t crc_at = body - kSlotTrailerBytes;
  if (detail::get_u32(p + crc_at) != crc32(bytes.first(crc_at))) return std::nullopt;
  return SlotView{detail::get_u32(p + 4), bytes.subspan(kSlotHeaderBytes, length)};
}

/// Whether sequence a is newer than b (serial-number arithmetic: correct across the wrap).
constexpr bool newer(uint32_t a, uint32_t b) noexcept {
  return static_cast<int32_t>(a - b) > 0;
}

}  // namespace imd::hal
