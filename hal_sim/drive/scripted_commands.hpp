#pragma once
/// The host side of a scenario's [[can_commands]]: every frame the script sends, in time order,
/// encoded with the protocol table, the node's alive counter and the E2E CRC (or deliberately
/// broken, as the entry asks).
#include <cstdint>
#include <vector>

#include "hal/can_bus.hpp"
#include "hal_sim/scenario.hpp"

namespace imd::sim {

struct ScriptedFrame {
  uint64_t tick = 0;  ///< delivered before this tick runs
  hal::CanFrame frame;
};

/// Checks every entry against the protocol table and expands the repeats up to the end of the
/// run. Throws ConfigError naming can_commands[i] and the key for an unknown message, a message
/// the drive does not receive, an unknown field or a value its signal cannot carry.
std::vector<ScriptedFrame> scripted_frames(const Scenario& scenario);

}  // namespace imd::sim
