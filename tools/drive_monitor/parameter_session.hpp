#pragma once
/// One conversation with a drive's motor record on a live bus (drive_monitor parameters and
/// identify): each access waits for its answer, and a busy drive (still applying the last
/// write) is asked again until the wait runs out.
#include <chrono>
#include <optional>
#include <string>
#include <thread>

#include "firmware/protocol/commands.hpp"
#include "tools/drive_monitor/cli_io.hpp"
#include "tools/drive_monitor/parameter_access.hpp"

namespace imd::monitor::cli {

class ParameterSession {
 public:
  ParameterSession(LiveBus& bus, uint8_t node, uint8_t counter, double wait_s)
      : bus_(bus), node_(node), encoder_(node, counter), wait_s_(wait_s) {}

  std::optional<ParameterReply> access(firmware::protocol::ParameterOp op, uint8_t field,
                                       float value = 0.0f) {
    using firmware::protocol::ParameterOp;
    const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                             std::chrono::duration<double>(wait_s_));
    while (g_stop == 0) {
      if (!bus_.try_send(encoder_.encode(parameter_command(op, field, value)))) return {};
      std::optional<ParameterReply> reply;
      receive_until(bus_, wait_s_, [&](const hal::CanFrame& f) {
        reply = decode_parameter_value(f, node_);
        return reply && reply->op == op && (op == ParameterOp::save || reply->field == field);
      });
      if (!reply || reply->status != firmware::ParameterStatus::busy || Clock::now() >= deadline) {
        return reply;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return {};
  }
  /// Another command on the same alive counter sequence (the drive checks one per node).
  hal::CanFrame encode(const firmware::protocol::Command& c) { return encoder_.encode(c); }

 private:
  LiveBus& bus_;
  uint8_t node_;
  firmware::protocol::CommandEncoder encoder_;
  double wait_s_;
};

/// The alive counter a session starts from: one past the last command the drive accepted, as
/// its heartbeat says. Without a heartbeat within `wait_s`, prints why and returns nullopt.
std::optional<uint8_t> first_counter(LiveBus& bus, uint8_t node, const std::string& can,
                                     double wait_s);

/// Reads every field of the record and prints it; with `motor_out`, writes the motor as a motor
/// file named after the node. Returns 0, or an exit code with its message printed.
int read_record(ParameterSession& session, int node, const std::string& can,
                const std::string& motor_out);

}  // namespace imd::monitor::cli
