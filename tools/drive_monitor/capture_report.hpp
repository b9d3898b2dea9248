#pragma once
/// A shared bus carries more than the watched drive's frames: error frames, 29-bit and CAN FD
/// traffic, remote requests, other nodes. watch decodes the drive's frames, skips and counts
/// the rest, and ends with one summary line, and with a warning when the watched node was not
/// heard at all (drive_monitor then exits with kExitNoAnswer).
#include <cstdint>
#include <optional>
#include <string>

#include "hal/can_bus.hpp"
#include "tools/can_log/candump_frame.hpp"
#include "tools/drive_monitor/monitor.hpp"

namespace imd::monitor {

/// Frames that are not classic data frames with an 11-bit identifier: the drive's protocol
/// has none of them, so they never reach DriveMonitor.
struct SkippedFrames {
  uint64_t error = 0;     ///< error frames (a controller's report, not a node's frame)
  uint64_t extended = 0;  ///< classic data frames with a 29-bit identifier
  uint64_t fd = 0;        ///< CAN FD frames, whatever their identifier
  uint64_t remote = 0;    ///< remote requests, whatever their identifier
  /// Live bus only: frames the interface dropped as not classic 11-bit data (29-bit or
  /// remote; it does not tell them apart, and a classic socket receives no CAN FD).
  uint64_t unsupported = 0;
  /// Not in the capture: frames its socket lost (candump -d's DROPCOUNT lines), not in total().
  uint64_t capture_lost = 0;

  uint64_t total() const noexcept { return error + extended + fd + remote + unsupported; }
};

/// A log frame for the monitor: the classic 11-bit frame, or nullopt after counting why not.
std::optional<hal::CanFrame> take_frame(const can_log::LogFrame& frame, SkippedFrames& skipped);

/// Frames the watched node sent that decoded by the table (drive-to-host messages): the
/// evidence that it was on the bus. Commands to it do not count: any host may send them.
uint64_t frames_from_node(const FrameCounts& counts) noexcept;

/// One line: every frame seen, how many decoded, and each reason for skipping, e.g.
/// "412 frames: 380 decoded (372 from node 1, 8 commands to it); skipped: 3 error frames, 2 with
/// 29-bit ids, 2 CAN FD, 1 remote, 20 of other nodes (node 2: 20), 1 of unknown messages, 3 of
/// wrong length".
/// With `live`, the error count is the interface's, and 29-bit and remote are one count. Frames
/// the capture lost end the line when there were any: "; the capture lost 3 frames".
std::string summary_line(const DriveStatus& status, const SkippedFrames& skipped, uint8_t node_id,
                         bool live);

/// When no frame came from `node_id`: the warning, naming the nodes that were heard (a wrong
/// --node is the usual cause); nullopt when the node was heard.
std::optional<std::string> silent_node_warning(const DriveStatus& status, uint8_t node_id,
                                               const std::string& source);

}  // namespace imd::monitor
