#pragma once
/// The latched faults as one 1-bit signal per fault code, so that DBC tools name each fault
/// instead of showing a number: signal fault_<name> of fault code n sits at bit (bit0 + n) of
/// its frame, where bit0 is the first bit of the drive's 16-bit fault word (bit n = fault code
/// n). Code 0 ("none") is never latched: its bit stays unused and has no signal.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "firmware/protocol/value_tables.hpp"

namespace imd::firmware::protocol {

inline constexpr std::size_t kFaultCodes = std::size(kFaultValues);
inline constexpr std::size_t kFaultBitSignals = kFaultCodes - 1;  ///< codes 1..15

/// The signal names, by fault code (code 0 has none).
inline constexpr const char* kFaultBitNames[kFaultCodes] = {
    "",
    "fault_adc_offset",
    "fault_overcurrent",
    "fault_magnetizing_timeout",
    "fault_non_finite",
    "fault_singular_control",
    "fault_bus_undervoltage",
    "fault_bus_overvoltage",
    "fault_overrun",
    "fault_overspeed",
    "fault_encoder",
    "fault_adc_stuck",
    "fault_phase_loss",
    "fault_command_timeout",
    "fault_emergency_stop",
    "fault_enable_input",
};

/// Every name is "fault_" and the fault's name in kFaultValues, at its code.
constexpr bool fault_bit_names_match() noexcept {
  constexpr std::string_view kPrefix = "fault_";
  for (std::size_t code = 1; code < kFaultCodes; ++code) {
    const std::string_view name = kFaultBitNames[code];
    if (kFaultValues[code].raw != int32_t(code) || !name.starts_with(kPrefix) ||
        name.substr(kPrefix.size()) != kFaultValues[code].name) {
      return false;
    }
  }
  return true;
}
static_assert(kFaultCodes <= 16, "the fault word has 16 bits");
static_assert(fault_bit_names_match(), "kFaultBitNames must follow kFaultValues");

/// The fault-bit signals of a message whose fault word starts at `bit0`.
constexpr std::array<Signal, kFaultBitSignals> fault_bit_signals(uint8_t bit0) noexcept {
  std::array<Signal, kFaultBitSignals> signals{};
  for (std::size_t code = 1; code < kFaultCodes; ++code) {
    signals[code - 1] = Signal{kFaultBitNames[code], static_cast<uint8_t>(bit0 + code), 1, false,
                               1, 1, 0.0f, "", "1: latched since start or the last clear_faults"};
  }
  return signals;
}

/// A message's own signals followed by its fault bits, as one table.
template <std::size_t N, std::size_t M>
constexpr std::array<Signal, N + M> join(const Signal (&head)[N],
                                         const std::array<Signal, M>& tail) noexcept {
  std::array<Signal, N + M> all{};
  for (std::size_t i = 0; i < N; ++i) all[i] = head[i];
  for (std::size_t i = 0; i < M; ++i) all[N + i] = tail[i];
  return all;
}

/// The fault code a signal stands for, or -1 when it is not a fault bit.
constexpr int fault_code_of(const Signal& s) noexcept {
  if (s.length_bits != 1) return -1;
  for (std::size_t code = 1; code < kFaultCodes; ++code) {
    if (std::string_view(s.name) == kFaultBitNames[code]) return static_cast<int>(code);
  }
  return -1;
}

/// The codes 1..15 of the fault word as one field, to pack and unpack them in one step; never
/// in the table.
constexpr Signal fault_word(uint8_t bit0) noexcept {
  return Signal{"fault_word", static_cast<uint8_t>(bit0 + 1), kFaultBitSignals, false};
}

/// Writes the latched faults (bit n = fault code n) to the fault bits at `bit0`. Tick context.
constexpr void set_fault_bits(Payload& data, uint8_t bit0, uint16_t bits) noexcept {
  set_raw(data, fault_word(bit0), bits >> 1);
}
/// The latched faults (bit n = fault code n) of the fault bits at `bit0`.
constexpr uint16_t get_fault_bits(const Payload& data, uint8_t bit0) noexcept {
  return static_cast<uint16_t>(get_raw(data, fault_word(bit0)) << 1);
}

}  // namespace imd::firmware::protocol
