#pragma once
/// Command frames: the typed commands, the decoder the drive runs on every received frame, and
/// the encoder hosts use (drive_monitor, the simulator's scripted commands).
///
/// A frame is rejected, counted and reported (and changes nothing) when its length is not the
/// message's, its CRC is wrong, its alive counter repeats the last one or jumps by more than
/// kMaxCounterStep (a stale or replayed frame), or a value is out of range. A frame that passes
/// the length, CRC and counter checks sets the counter reference even if its value is refused,
/// because the host's counter moved on; the first frame after start-up sets it too. The
/// emergency stop skips the counter check. One counter covers all commands of a node, so a host
/// that starts late learns where it stands from the heartbeat's command_counter.
#include <algorithm>
#include <array>
#include <cstdint>
#include <iterator>

#include "firmware/protocol/messages.hpp"
#include "hal/can_bus.hpp"

namespace imd::firmware::protocol {

enum class CommandKind : uint8_t {
  emergency_stop,
  disable,
  enable,
  clear_faults,
  set_speed,           ///< value: rad/s
  set_flux,            ///< value: Wb^2
  select_controller,   ///< value: 0 dsmc, 1 iol, 2 ifoc
  set_telemetry_rate,  ///< value: Hz
  parameter_access,    ///< op (read, write, save), field, value (write)
  identify,            ///< start the commissioning
};

/// What a parameter_access frame asks (kParameterOpValues); the last two are the drive's own
/// requests to its service loop, never on CAN.
enum class ParameterOp : uint8_t { read, write, save, identify, identified };
inline constexpr int kParameterOpCount = 3;  ///< the operations a frame may carry

struct Command {
  CommandKind kind = CommandKind::disable;
  float value = 0.0f;
  ParameterOp op = ParameterOp::read;  ///< parameter_access only
  uint8_t field = 0;                   ///< parameter_access only: the record's field index
};

/// Why a frame was rejected (the numbering is kCommandResultValues').
enum class CommandResult : uint8_t {
  accepted = 0,
  wrong_length,
  bad_crc,
  repeated_counter,
  stale_counter,
  out_of_range,
  not_allowed,  ///< valid, but not in the drive's present state (set by the application)
  unknown_message,
  not_in_image,  ///< a law or the commissioning that this firmware image does not carry
};
inline constexpr int kCommandResultCount = 9;
static_assert(std::size(kCommandResultValues) == kCommandResultCount,
              "every command result has its name in the protocol's value table");

/// Largest accepted counter step: up to two lost frames in a row.
inline constexpr uint8_t kMaxCounterStep = 3;

/// The ranges the decoder enforces; the application sets them from its configuration.
struct CommandLimits {
  float max_speed_rad_s = 400.0f;  ///< |set_speed| <= this (the overspeed threshold)
  float min_flux2_Wb2 = 0.01f;     ///< set_flux >= this (well away from a singular B_k)
  float max_flux2_Wb2 = 4.0f;      ///< set_flux <= this
};

/// The limits within the protocol's widest ranges, which the DBC states: no configuration makes
/// a drive accept a reference beyond kMaxSpeedReference_rad_s or kMaxFlux2Reference_Wb2.
constexpr CommandLimits within_protocol(CommandLimits l) noexcept {
  l.max_speed_rad_s = std::min(l.max_speed_rad_s, kMaxSpeedReference_rad_s);
  l.max_flux2_Wb2 = std::min(l.max_flux2_Wb2, kMaxFlux2Reference_Wb2);
  return l;
}

struct Decoded {
  bool for_this_node = false;  ///< false: another node's frame or telemetry, ignored silently
  CommandResult result = CommandResult::unknown_message;
  uint8_t message_id = 0;
  uint8_t counter = 0;
  Command command;
};

/// The drive side. No heap, noexcept: runs in tick context.
class CommandDecoder {
 public:
  CommandDecoder(uint8_t node_id, const CommandLimits& limits) noexcept
      : node_id_(node_id), limits_(within_protocol(limits)) {}

  /// Checks a frame and, if it is a valid command for this node, advances the counter.
  Decoded decode(const hal::CanFrame& frame) noexcept;

  /// A command the application refuses (not allowed now, a value it cannot take, not in this
  /// image): counted like a rejection. `reason` is not `accepted`.
  void count_refused(CommandResult reason) noexcept {
    ++rejections_[int(reason)];
    ++rejected_total_;
  }

  uint32_t rejected(CommandResult reason) const noexcept { return rejections_[int(reason)]; }
  /// Every rejection so far (kept as it counts: the tick reports it every period).
  uint32_t rejected_total() const noexcept { return rejected_total_; }
  uint8_t last_counter() const noexcept { return last_counter_; }

 private:
  Decoded reject(Decoded d, CommandResult reason) noexcept;

  uint8_t node_id_;
  CommandLimits limits_;
  bool have_counter_ = false;
  uint8_t last_counter_ = 0;
  std::array<uint32_t, kCommandResultCount> rejections_{};
  uint32_t rejected_total_ = 0;
};

/// The host side: typed commands to frames with the next alive counter and the CRC.
class CommandEncoder {
 public:
  explicit CommandEncoder(uint8_t node_id, uint8_t first_counter = 0) noexcept
      : node_id_(node_id), counter_(first_counter & 0x0F) {}
  hal::CanFrame encode(const Command& command) noexcept;
  /// The counter the next frame will carry.
  uint8_t next_counter() const noexcept { return counter_; }
  void set_next_counter(uint8_t counter) noexcept { counter_ = counter & 0x0F; }

 private:
  uint8_t node_id_;
  uint8_t counter_;
};

/// The message that carries a command kind.
MessageId message_for(CommandKind kind) noexcept;

}  // namespace imd::firmware::protocol
