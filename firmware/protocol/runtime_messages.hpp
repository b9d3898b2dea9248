#pragma once
/// The message tables the firmware reads at run time (packing telemetry, decoding commands).
/// With the documentation text (host builds) they are kMessages itself. Without it (the
/// bare-metal images) they are copies of kMessages without the messages' names and the fault
/// bits, whose signals have no name and no value table: the names are read at compile time
/// only (signal_of, find_signal), so the named tables are never emitted and their strings stay
/// out of the image. Tick context.
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>

#include "firmware/protocol/messages.hpp"

namespace imd::firmware::protocol {

#if IMD_PROTOCOL_DOC_TEXT
constexpr const Message* find_runtime_message(uint8_t message_id) noexcept {
  return find_message(message_id);
}
/// With the documentation text the run-time tables are the named ones: a copy keeps all.
constexpr Signal without_name(const Signal& s) noexcept {
  return s;
}
#else
/// `s` without its name and value table (a run-time copy keeps neither).
constexpr Signal without_name(const Signal& s) noexcept {
  Signal copy = s;
  copy.name = nullptr;
  copy.values = {};
  return copy;
}

namespace detail {
/// A message's signals before its fault bits (they come last, and the firmware packs them as one
/// fault word: fault_bits.hpp).
constexpr std::size_t own_signal_count(const Message& m) noexcept {
  std::size_t n = 0;
  while (n < m.signals.size() && fault_code_of(m.signals[n]) < 0) ++n;
  return n;
}

template <std::size_t I>
inline constexpr auto kNamelessSignals = [] {
  std::array<Signal, own_signal_count(kMessages[I])> signals{};
  for (std::size_t j = 0; j < signals.size(); ++j)
    signals[j] = without_name(kMessages[I].signals[j]);
  return signals;
}();

template <std::size_t... I>
constexpr std::array<Message, kMessageCount> nameless_messages(std::index_sequence<I...>) noexcept {
  std::array<Message, kMessageCount> messages{kMessages[I]...};
  ((messages[I].signals = kNamelessSignals<I>, messages[I].name = nullptr), ...);
  return messages;
}
inline constexpr std::array<Message, kMessageCount> kNamelessMessages =
    nameless_messages(std::make_index_sequence<kMessageCount>{});
}  // namespace detail

/// The copies pack and unpack as the named tables do: every field but the name and the value
/// table is the same, in the same order, and all the signals they leave out are fault bits.
constexpr bool same_packing(const Signal& a, const Signal& b) noexcept {
  return a.start_bit == b.start_bit && a.length_bits == b.length_bits &&
         a.is_signed == b.is_signed && a.scale_num == b.scale_num && a.scale_den == b.scale_den &&
         a.offset == b.offset && a.is_float == b.is_float && a.has_range == b.has_range &&
         a.range_min == b.range_min && a.range_max == b.range_max;
}
static_assert(
    [] {
      for (std::size_t i = 0; i < kMessageCount; ++i) {
        const Message& named = kMessages[i];
        const Message& copy = detail::kNamelessMessages[i];
        if (copy.id != named.id || copy.length != named.length ||
            copy.direction != named.direction || copy.signals.size() > named.signals.size()) {
          return false;
        }
        for (std::size_t j = 0; j < named.signals.size(); ++j) {
          if (j >= copy.signals.size() ? fault_code_of(named.signals[j]) < 0
                                       : !same_packing(copy.signals[j], named.signals[j]) ||
                                             copy.signals[j].name != nullptr) {
            return false;
          }
        }
      }
      return true;
    }(),
    "the run-time tables pack as the named ones");

constexpr const Message* find_runtime_message(uint8_t message_id) noexcept {
  const bool known = message_id < kMessageIndex.size() && kMessageIndex[message_id] < kMessageCount;
  return known ? &detail::kNamelessMessages[kMessageIndex[message_id]] : nullptr;
}
#endif

/// The run-time table entry of a message id that exists.
constexpr const Message& runtime_message(MessageId id) noexcept {
  return *find_runtime_message(uint8_t(id));
}

/// A signal by name as a run-time value (a constant's initializer): looked up in the named
/// table at compile time, copied without its name.
constexpr Signal runtime_signal_of(MessageId id, const char* name) noexcept {
  return without_name(signal_of(id, name));
}

}  // namespace imd::firmware::protocol
