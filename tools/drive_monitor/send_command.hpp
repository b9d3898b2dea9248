#pragma once
/// drive_monitor send: command names and values checked locally before anything goes on the
/// bus, and the frames the send waits for (heartbeat, command_ack).
#include <cstdint>
#include <optional>
#include <string>

#include "firmware/protocol/commands.hpp"
#include "hal/can_bus.hpp"

namespace imd::monitor {

/// The command words of the CLI, e.g. "enable, disable, ..., set-telemetry-rate HZ".
std::string command_usage();

/// A command from its CLI word and optional value text ("set-speed", "12.5"). On a bad name, a
/// missing or extra value, a non-number or a value the signal cannot represent returns nullopt
/// and sets `error` (e.g. "set-speed: 'fast' is not a number").
std::optional<firmware::protocol::Command> parse_command(const std::string& name,
                                                         const std::optional<std::string>& value,
                                                         std::string& error);

/// The command as its frame will carry it, e.g. "set_speed 12.500 rad/s", "select_controller iol".
std::string describe_command(const firmware::protocol::Command& command);

/// The heartbeat's command_counter if `frame` is node `node_id`'s heartbeat.
std::optional<uint8_t> heartbeat_command_counter(const hal::CanFrame& frame, uint8_t node_id);

/// The acknowledgement of a command frame.
struct Ack {
  firmware::protocol::CommandResult result;
  uint16_t rejected_total;
};

/// A command_ack and the frame it answers.
struct AckFrame {
  uint8_t message_id;
  uint8_t counter;
  Ack ack;
};

/// The ack if `frame` is node `node_id`'s command_ack, for whichever frame it answers.
std::optional<AckFrame> decode_ack(const hal::CanFrame& frame, uint8_t node_id);

/// The ack if `frame` is node `node_id`'s command_ack for message `message_id` with `counter`.
std::optional<Ack> match_ack(const hal::CanFrame& frame, uint8_t node_id, uint8_t message_id,
                             uint8_t counter);

/// The name of a command result ("accepted", "bad_crc", ...).
std::string result_name(firmware::protocol::CommandResult result);

}  // namespace imd::monitor
