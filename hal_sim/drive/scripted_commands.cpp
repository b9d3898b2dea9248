#include "hal_sim/drive/scripted_commands.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "firmware/protocol/e2e.hpp"
#include "firmware/protocol/messages.hpp"
#include "hal_sim/config_error.hpp"

namespace imd::sim {
namespace {

namespace protocol = firmware::protocol;

std::string command_names() {
  std::string names;
  for (const protocol::Message& m : protocol::kMessages) {
    if (m.direction != protocol::Direction::host_to_drive) continue;
    names += names.empty() ? "" : ", ";
    names += m.name;
  }
  return names;
}

const protocol::Message& find_command(const Scenario& s, const CanCommandScript& c) {
  for (const protocol::Message& m : protocol::kMessages) {
    if (c.message == m.name) {
      if (m.direction != protocol::Direction::host_to_drive) break;
      return m;
    }
  }
  throw ConfigError(fmt::format("{}: can_commands[{}].message = \"{}\": not a command (one of: {})",
                                s.source, c.index, c.message, command_names()));
}

hal::CanFrame encode(const Scenario& s, const CanCommandScript& c, const protocol::Message& m,
                     uint8_t counter) {
  hal::CanFrame frame;
  frame.id = protocol::can_id(uint8_t(s.can_node_id), m.id);
  frame.length = m.length;
  for (const auto& [name, value] : c.fields) {
    const int i = protocol::find_signal(m, name.c_str());
    if (i < 2) {  // the CRC and the counter are not fields: the entry has its own keys for them
      throw ConfigError(fmt::format("{}: can_commands[{}].fields.{}: {} has no such field",
                                    s.source, c.index, name, m.name));
    }
    const protocol::Signal& signal = m.signals[std::size_t(i)];
    if (!std::isfinite(value) || !protocol::in_range(signal, float(value))) {
      throw ConfigError(
          fmt::format("{}: can_commands[{}].fields.{} = {}: outside what the signal "
                      "carries ({} .. {} {})",
                      s.source, c.index, name, value, double(signal.raw_min()) * signal.scale(),
                      double(signal.raw_max()) * signal.scale(), signal.unit));
    }
    protocol::set_physical(frame.data, signal, float(value));
  }
  protocol::e2e_protect(frame.id, frame.data, frame.length, counter);
  if (c.corrupt_crc) frame.data[0] ^= 0xFF;
  if (c.length) frame.length = uint8_t(*c.length);
  return frame;
}

}  // namespace

std::vector<ScriptedFrame> scripted_frames(const Scenario& s) {
  struct Pending {
    double t_s;
    const CanCommandScript* script;
    const protocol::Message* message;
  };
  std::vector<Pending> pending;
  for (const CanCommandScript& c : s.can_commands) {
    const protocol::Message& m = find_command(s, c);
    const double end_s = std::min(c.until_s, s.duration_s);
    // Repeats at at_s + n every_s (no accumulated rounding), at most one per tick.
    const double count = c.every_s > 0 ? std::floor((end_s - c.at_s) / c.every_s + 1e-9) : 0.0;
    if (c.every_s > 0 && c.every_s < s.sample_period_s) {
      throw ConfigError(
          fmt::format("{}: can_commands[{}].every_s = {}: shorter than the sample "
                      "period ({} s)",
                      s.source, c.index, c.every_s, s.sample_period_s));
    }
    for (double n = 0; n <= count; ++n) pending.push_back({c.at_s + n * c.every_s, &c, &m});
  }
  std::stable_sort(pending.begin(), pending.end(),
                   [](const Pending& a, const Pending& b) { return a.t_s < b.t_s; });
  // One alive counter for the node, as a host keeps it; a forced counter does not advance it.
  uint8_t counter = 0;
  std::vector<ScriptedFrame> frames;
  frames.reserve(pending.size());
  for (const Pending& p : pending) {
    const uint8_t used = p.script->counter ? uint8_t(*p.script->counter) : counter;
    if (!p.script->counter) counter = uint8_t((counter + 1) & 0x0F);
    const auto tick = static_cast<uint64_t>(std::ceil(p.t_s / s.sample_period_s - 1e-9));
    frames.push_back({tick, encode(s, *p.script, *p.message, used)});
  }
  return frames;
}

}  // namespace imd::sim
