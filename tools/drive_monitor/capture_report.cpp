#include "tools/drive_monitor/capture_report.hpp"

#include <fmt/format.h>

namespace imd::monitor {
namespace {

/// "node 2: 20, node 5: 3" for every other node heard.
std::string other_nodes_text(const FrameCounts& counts) {
  std::string text;
  for (std::size_t node = 0; node < counts.other_node_frames.size(); ++node) {
    if (counts.other_node_frames[node] == 0) continue;
    if (!text.empty()) text += ", ";
    text += fmt::format("node {}: {}", node, counts.other_node_frames[node]);
  }
  return text;
}

}  // namespace

std::optional<hal::CanFrame> take_frame(const can_log::LogFrame& frame, SkippedFrames& skipped) {
  switch (frame.type) {
    case can_log::FrameType::error:
      ++skipped.error;
      return std::nullopt;
    case can_log::FrameType::fd:
      ++skipped.fd;
      return std::nullopt;
    case can_log::FrameType::remote:
      ++skipped.remote;
      return std::nullopt;
    case can_log::FrameType::data:
      break;
  }
  if (frame.extended) {
    ++skipped.extended;
    return std::nullopt;
  }
  return can_log::classic_frame(frame);
}

uint64_t frames_from_node(const FrameCounts& counts) noexcept {
  return counts.decoded - counts.commands;
}

std::string summary_line(const DriveStatus& status, const SkippedFrames& skipped, uint8_t node_id,
                         bool live) {
  const FrameCounts& c = status.frames;
  std::string text = fmt::format(
      "{} frames: {} decoded ({} from node {}, {} commands to it); skipped: {} error frames",
      c.total + skipped.total(), c.decoded, frames_from_node(c), node_id, c.commands,
      skipped.error);
  if (live) {
    text += fmt::format(", {} with 29-bit ids or remote", skipped.unsupported);
  } else {
    text += fmt::format(", {} with 29-bit ids, {} CAN FD, {} remote", skipped.extended, skipped.fd,
                        skipped.remote);
  }
  text += fmt::format(", {} of other nodes", c.other_nodes);
  if (c.other_nodes > 0) text += " (" + other_nodes_text(c) + ")";
  text += fmt::format(", {} of unknown messages, {} of wrong length", c.unknown, c.wrong_length);
  if (skipped.capture_lost > 0) {
    text += fmt::format("; the capture lost {} frames", skipped.capture_lost);
  }
  return text;
}

std::optional<std::string> silent_node_warning(const DriveStatus& status, uint8_t node_id,
                                               const std::string& source) {
  const FrameCounts& c = status.frames;
  if (frames_from_node(c) > 0) return std::nullopt;
  std::string text = fmt::format("warning: no frame from node {} on {}", node_id, source);
  if (c.commands > 0) text += fmt::format(" ({} commands to it)", c.commands);
  if (c.other_nodes > 0) {
    text += "; heard only other nodes (" + other_nodes_text(c) + "): is --node right?";
  } else {
    text += "; no other node either";
  }
  return text;
}

}  // namespace imd::monitor
