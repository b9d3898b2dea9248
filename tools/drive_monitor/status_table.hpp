#pragma once
/// The drive's status as a text table, for the terminal (drive_monitor watch).
#include <cstdint>
#include <string>

#include "tools/drive_monitor/monitor.hpp"

namespace imd::monitor {

/// What the CAN interface itself reported (live mode only).
struct BusInfo {
  uint32_t error_frames = 0;
  uint32_t bus_off_events = 0;
  bool bus_off = false;
  std::string last_error_class;  ///< e.g. "bus-off"; "none"
  uint32_t unsupported_frames = 0;
};

/// The table: one line per topic, "  label  text", newline-terminated lines. `source` names
/// where the frames come from (an interface or a log file); `bus` may be null.
std::string render_table(const DriveStatus& status, uint8_t node_id, const std::string& source,
                         const BusInfo* bus = nullptr);

}  // namespace imd::monitor
