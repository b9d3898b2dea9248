#pragma once
/// drive_monitor parameters: the motor record's fields by name, KEY=VALUE assignments checked
/// locally, and the drive's parameter_value answers decoded (docs/can/protocol.md).
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "firmware/drive_state.hpp"
#include "firmware/parameters/motor_record.hpp"
#include "firmware/protocol/commands.hpp"
#include "hal/can_bus.hpp"

namespace imd::monitor {

/// The field of this name ("Rs_Ohm", ... as in a motor file and the DBC), or nullopt.
std::optional<uint8_t> field_named(std::string_view name);
/// "Rs_Ohm, Ls_H, ..." for usage and error texts.
std::string field_names();
std::string field_name(uint8_t field);
std::string status_name(firmware::ParameterStatus status);

struct Assignment {
  uint8_t field;
  float value;
};
/// "KEY=VALUE" with a known key and a finite number (the drive checks the rules and answers;
/// this only keeps typos off the bus). Sets `error` on failure.
std::optional<Assignment> parse_assignment(const std::string& text, std::string& error);

/// The parameter_access command for an operation on a field.
firmware::protocol::Command parameter_command(firmware::protocol::ParameterOp op, uint8_t field,
                                              float value = 0.0f);

struct ParameterReply {
  uint8_t field;
  firmware::protocol::ParameterOp op;
  firmware::ParameterStatus status;
  float value;  ///< NaN: no value
  bool complete, saved;
};
/// The answer if `frame` is node `node_id`'s parameter_value.
std::optional<ParameterReply> decode_parameter_value(const hal::CanFrame& frame, uint8_t node_id);

struct IdentifyProgress {
  uint8_t step, failure;
  float fraction, seconds;
  bool running() const noexcept { return step <= 3 || (step >= 7 && step <= 11); }
  bool ended() const noexcept { return step == 4 || step == 5; }
};
/// The progress if `frame` is node `node_id`'s identify_progress.
std::optional<IdentifyProgress> decode_identify_progress(const hal::CanFrame& frame,
                                                         uint8_t node_id);
/// The drive state if `frame` is node `node_id`'s heartbeat.
std::optional<firmware::DriveState> heartbeat_state(const hal::CanFrame& frame, uint8_t node_id);
/// "accelerate 40 % (12.3 s)", or "done (14.1 s)", "failed: not_settled (60.2 s)".
std::string progress_text(const IdentifyProgress& p);

}  // namespace imd::monitor
