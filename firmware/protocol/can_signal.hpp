#pragma once
/// A signal inside a classic CAN frame: Intel (little-endian) bit order, the DBC convention.
/// physical = raw * scale + offset, with scale = scale_num / scale_den so that the DBC shows it
/// exactly and the MCU packs it in single precision. No heap; usable in tick context.
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <span>

/// Whether the tables keep their documentation text (units and comments, which the DBC and the
/// protocol page are written from). The bare-metal images build with 0: nothing on the board
/// reads that text, and it is most of the tables' flash.
#ifndef IMD_PROTOCOL_DOC_TEXT
#define IMD_PROTOCOL_DOC_TEXT 1
#endif

namespace imd::firmware::protocol {

#if IMD_PROTOCOL_DOC_TEXT
using DocText = const char*;
#else
/// Takes a string literal and keeps none of it: the literal is not emitted, and with
/// [[no_unique_address]] the member takes no room. Reading it fails to compile.
struct DocText {
  consteval DocText(const char*) noexcept {}  // NOLINT(google-explicit-constructor): literals
};
#endif

/// A named raw value of an enumerated signal (a DBC VAL_ entry).
struct ValueName {
  int32_t raw;
  const char* name;
};

struct Signal {
  const char* name;
  uint8_t start_bit;  ///< bit position of the least-significant bit
  uint8_t length_bits;
  bool is_signed;
  int32_t scale_num = 1;
  int32_t scale_den = 1;
  float offset = 0.0f;
  [[no_unique_address]] DocText unit = "";
  [[no_unique_address]] DocText comment = "";
  std::span<const ValueName> values = {};
  /// An IEEE 754 single-precision value in 32 bits (a DBC SIG_VALTYPE_ 1 signal); the scale is
  /// 1 and the offset 0.
  bool is_float = false;
  /// The physical values the drive accepts, when narrower than the raw range (commands): the
  /// DBC's [min|max]. Without it the DBC shows the raw range. Set with with_range().
  bool has_range = false;
  float range_min = 0.0f;
  float range_max = 0.0f;

  constexpr double scale() const noexcept { return double(scale_num) / double(scale_den); }
  constexpr int64_t raw_min() const noexcept {
    return is_signed ? -(int64_t(1) << (length_bits - 1)) : 0;
  }
  constexpr int64_t raw_max() const noexcept {
    return is_signed ? (int64_t(1) << (length_bits - 1)) - 1 : (int64_t(1) << length_bits) - 1;
  }
};

/// `s` with the physical range [min, max] the drive accepts.
constexpr Signal with_range(Signal s, float min, float max) noexcept {
  s.has_range = true;
  s.range_min = min;
  s.range_max = max;
  return s;
}

using Payload = std::array<uint8_t, 8>;

/// The mask of a signal's bits, from bit 0.
constexpr uint64_t field_mask(const Signal& s) noexcept {
  return s.length_bits >= 64 ? ~uint64_t(0) : (uint64_t(1) << s.length_bits) - 1;
}

/// The raw bits of a signal in their place in the payload read as one little-endian word. The
/// mask is taken in 32 bits (no signal is wider: frame_codec.hpp), which spares the MCU a
/// 64-bit mask; only the shift into place is 64-bit.
constexpr uint64_t placed(const Signal& s, int64_t raw) noexcept {
  const uint32_t mask = s.length_bits >= 32 ? ~uint32_t{0} : (uint32_t{1} << s.length_bits) - 1u;
  return uint64_t{static_cast<uint32_t>(raw) & mask} << s.start_bit;
}

/// The payload as one little-endian word, and back: on a little-endian machine (the MCU, x86-64,
/// AArch64) the bytes as they are, else byte by byte.
constexpr uint64_t payload_word(const Payload& data) noexcept {
  if constexpr (std::endian::native == std::endian::little) return std::bit_cast<uint64_t>(data);
  uint64_t bits = 0;
  for (int i = 0; i < 8; ++i) bits |= uint64_t(data[i]) << (8 * i);
  return bits;
}
constexpr void set_payload_word(Payload& data, uint64_t bits) noexcept {
  if constexpr (std::endian::native == std::endian::little) {
    data = std::bit_cast<Payload>(bits);
  } else {
    for (int i = 0; i < 8; ++i) data[i] = static_cast<uint8_t>(bits >> (8 * i));
  }
}

/// The raw bits of a signal (sign-extended for signed signals).
constexpr int64_t get_raw(const Payload& data, const Signal& s) noexcept {
  const uint64_t mask = field_mask(s);
  uint64_t raw = (payload_word(data) >> s.start_bit) & mask;
  if (s.is_signed && s.length_bits < 64 && (raw >> (s.length_bits - 1)) != 0) raw |= ~mask;
  return static_cast<int64_t>(raw);
}

/// Writes the raw bits of a signal; `raw` must be within [raw_min, raw_max].
constexpr void set_raw(Payload& data, const Signal& s, int64_t raw) noexcept {
  set_payload_word(data, (payload_word(data) & ~(field_mask(s) << s.start_bit)) | placed(s, raw));
}

/// The physical value of a signal, in single precision (what the MCU decodes with).
inline float get_physical(const Payload& data, const Signal& s) noexcept {
  const int64_t raw = get_raw(data, s);
  if (s.is_float) return std::bit_cast<float>(static_cast<uint32_t>(raw));
  // No signal is wider than 32 bits (frame_codec.hpp): one 32-bit conversion, not a 64-bit
  // one (a library call on the MCU).
  const float value =
      s.is_signed ? float(static_cast<int32_t>(raw)) : float(static_cast<uint32_t>(raw));
  return value * float(s.scale_num) / float(s.scale_den) + s.offset;
}

/// std::round (halves away from zero) without its library call on the MCU: below 2^23 the
/// conversion to an integer truncates exactly, and the fraction x - trunc(x) is exact too.
/// Larger magnitudes, infinities and NaN are returned as they are (they are whole or not
/// numbers). A zero comes back as +0 where std::round keeps -0; the raw values are the same.
inline float round_half_away(float x) noexcept {
  if (!(std::fabs(x) < 8388608.0f)) return x;
  const float whole = static_cast<float>(static_cast<int32_t>(x));
  const float fraction = x - whole;
  if (fraction >= 0.5f) return whole + 1.0f;
  if (fraction <= -0.5f) return whole - 1.0f;
  return whole;
}

/// raw_min() and raw_max() as floats, as a conversion of the 64-bit values gives them, from
/// 32-bit integers: a 64-bit conversion is a library call on the MCU, and no signal is wider
/// than 32 bits (frame_codec.hpp checks the tables).
inline float raw_min_float(const Signal& s) noexcept {
  return s.is_signed ? -static_cast<float>(uint32_t{1} << (s.length_bits - 1)) : 0.0f;
}
inline float raw_max_float(const Signal& s) noexcept {
  const uint32_t max = s.is_signed           ? (uint32_t{1} << (s.length_bits - 1)) - 1u
                       : s.length_bits >= 32 ? ~uint32_t{0}
                                             : (uint32_t{1} << s.length_bits) - 1u;
  return static_cast<float>(max);
}

/// The nearest raw value for a physical value, saturated to the signal's range. A NaN becomes
/// raw_min: telemetry must never wrap around to a plausible value.
inline int64_t to_raw(const Signal& s, float value) noexcept {
  const float raw = round_half_away((value - s.offset) * float(s.scale_den) / float(s.scale_num));
  if (!(raw >= raw_min_float(s))) return s.raw_min();  // NaN and -Inf too
  if (raw >= raw_max_float(s)) return s.raw_max();
  // Inside the range, which 32 bits hold: one conversion (a 64-bit one is a library call in
  // double on the MCU).
  return s.is_signed ? int64_t{static_cast<int32_t>(raw)} : int64_t{static_cast<uint32_t>(raw)};
}

/// The raw value a physical value is sent as: a float's bits (NaN and infinities pass as they
/// are), else to_raw.
inline int64_t raw_of(const Signal& s, float value) noexcept {
  return s.is_float ? int64_t{std::bit_cast<uint32_t>(value)} : to_raw(s, value);
}

inline void set_physical(Payload& data, const Signal& s, float value) noexcept {
  set_raw(data, s, raw_of(s, value));
}

/// Whether a physical value is representable without saturation (any float in a float signal).
inline bool in_range(const Signal& s, float value) noexcept {
  if (s.is_float) return true;
  const float raw = round_half_away((value - s.offset) * float(s.scale_den) / float(s.scale_num));
  return raw >= raw_min_float(s) && raw <= raw_max_float(s);
}

}  // namespace imd::firmware::protocol
