#pragma once
/// Packs and unpacks whole messages by their table entry, in signal order.
#include <cstdint>
#include <initializer_list>

#include "firmware/protocol/messages.hpp"
#include "firmware/protocol/runtime_messages.hpp"
#include "hal/can_bus.hpp"

namespace imd::firmware::protocol {

// to_raw packs in single precision with 32-bit conversions (can_signal.hpp).
static_assert([] {
  for (const Message& m : kMessages) {
    for (const Signal& s : m.signals) {
      if (s.length_bits < 1 || s.length_bits > 32) return false;
    }
  }
  return true;
}(), "every signal is 1 to 32 bits long");

/// A frame of message `id` for node `node_id` with `values` (physical, in signal order; missing
/// values are 0, extra ones ignored). Saturates values outside a signal's range. Tick context.
inline hal::CanFrame encode_frame(uint8_t node_id, MessageId id,
                                  std::initializer_list<float> values) noexcept {
  const Message& m = runtime_message(id);
  hal::CanFrame frame;
  frame.id = can_id(node_id, id);
  frame.length = m.length;
  // The signals do not overlap (tests/firmware/test_protocol.cpp): each is or-ed into one word,
  // written out once (a read-modify-write of the payload per signal cost about 300
  // instructions each on the MCU, in 64-bit shifts).
  uint64_t bits = 0;
  std::size_t i = 0;
  for (const float value : values) {
    if (i >= m.signals.size()) break;
    const Signal& s = m.signals[i++];
    bits |= placed(s, raw_of(s, value));
  }
  set_payload_word(frame.data, bits);
  return frame;
}

/// The physical value of signal `index` of a frame, in double precision (host tools).
inline double decode_signal(const hal::CanFrame& frame, const Signal& s) noexcept {
  if (s.is_float) return double(get_physical(frame.data, s));
  return double(get_raw(frame.data, s)) * s.scale() + double(s.offset);
}

/// The name of an enumerated raw value, or nullptr.
constexpr const char* value_name(const Signal& s, int64_t raw) noexcept {
  for (const ValueName& v : s.values) {
    if (v.raw == raw) return v.name;
  }
  return nullptr;
}

}  // namespace imd::firmware::protocol
