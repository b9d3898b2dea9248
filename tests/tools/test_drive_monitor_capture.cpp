// drive_monitor on captures of a shared bus: what take_frame hands the monitor and what it
// counts instead, the exact counts of the checked-in capture tests/data/can/shared_bus.log,
// that its foreign traffic changes nothing in node 1's decoded values, the summary line, and
// the warning when the watched node is absent (tests/data/can/node2_only.log).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "firmware/protocol/frame_codec.hpp"
#include "tools/can_log/candump_log.hpp"
#include "tools/drive_monitor/capture_report.hpp"
#include "tools/drive_monitor/monitor.hpp"

namespace imd::monitor {
namespace {

/// What watch --log makes of a file of tests/data/can.
struct Watched {
  DriveStatus status;
  SkippedFrames skipped;
  std::vector<TelemetryRow> rows;
  std::vector<int64_t> row_time_us;  ///< each row's log time, exact
  std::string error;
};

Watched watch(const std::string& name, uint8_t node_id) {
  can_log::LogReader reader(std::string(IMD_SOURCE_DIR) + "/tests/data/can/" + name);
  DriveMonitor monitor(node_id);
  Watched w;
  can_log::ParsedLine line;
  while (reader.next(line)) {
    const auto frame = take_frame(line.frame, w.skipped);
    if (!frame) continue;
    if (const auto row = monitor.feed(line.time_s, *frame)) {
      w.rows.push_back(*row);
      w.row_time_us.push_back(line.time_us);
    }
  }
  w.error = reader.error();
  w.skipped.capture_lost = reader.dropped_frames();
  w.status = monitor.status();
  return w;
}

can_log::LogFrame log_frame(can_log::FrameType type, bool extended) {
  can_log::LogFrame f;
  f.type = type;
  f.extended = extended;
  f.id = 0x022;  // node 1's heartbeat identifier: only a classic 11-bit data frame is it
  f.length = 8;
  return f;
}

TEST(drive_monitor_capture, TakeFrameCountsWhatIsNotAClassicElevenBitDataFrame) {
  using can_log::FrameType;
  SkippedFrames skipped;
  EXPECT_FALSE(take_frame(log_frame(FrameType::error, false), skipped));
  EXPECT_FALSE(take_frame(log_frame(FrameType::data, true), skipped));
  EXPECT_FALSE(take_frame(log_frame(FrameType::fd, false), skipped));
  EXPECT_FALSE(take_frame(log_frame(FrameType::fd, true), skipped));  // FD first, then 29-bit
  EXPECT_FALSE(take_frame(log_frame(FrameType::remote, false), skipped));
  EXPECT_FALSE(take_frame(log_frame(FrameType::remote, true), skipped));
  const auto classic = take_frame(log_frame(FrameType::data, false), skipped);
  ASSERT_TRUE(classic.has_value());
  EXPECT_EQ(classic->id, 0x022);
  EXPECT_EQ(classic->length, 8);
  EXPECT_EQ(skipped.error, 1u);
  EXPECT_EQ(skipped.extended, 1u);
  EXPECT_EQ(skipped.fd, 2u);
  EXPECT_EQ(skipped.remote, 2u);
  EXPECT_EQ(skipped.total(), 6u);
}

TEST(drive_monitor_capture, CountsEveryFrameOfTheSharedBusCapture) {
  const Watched w = watch("shared_bus.log", 1);
  ASSERT_EQ(w.error, "");
  // shared_bus.log, 47 lines: monitor_sample.log's 31 frames (30 of node 1, of which 4 are
  // commands, and 1 of node 2) and 16 more: 3 error frames; 3 classic frames with 29-bit ids;
  // 2 CAN FD frames (one with node 1's heartbeat id, one 29-bit); 2 remote frames (node 1's
  // heartbeat id, a 29-bit id); 5 more of node 2; 1 of node 1 with message id 0x1F, unknown.
  // And one line "DROPCOUNT: dropped 2 CAN frames ...": frames the capture lost.
  EXPECT_EQ(w.skipped.error, 3u);
  EXPECT_EQ(w.skipped.extended, 3u);
  EXPECT_EQ(w.skipped.fd, 2u);
  EXPECT_EQ(w.skipped.remote, 2u);
  EXPECT_EQ(w.skipped.unsupported, 0u);
  EXPECT_EQ(w.skipped.capture_lost, 2u);
  const FrameCounts& c = w.status.frames;
  EXPECT_EQ(c.total, 37u);
  EXPECT_EQ(c.decoded, 30u);
  EXPECT_EQ(c.commands, 4u);
  EXPECT_EQ(frames_from_node(c), 26u);
  EXPECT_EQ(c.other_nodes, 6u);
  EXPECT_EQ(c.other_node_frames[2], 6u);
  EXPECT_EQ(c.unknown, 1u);
  EXPECT_EQ(c.wrong_length, 0u);
  EXPECT_EQ(summary_line(w.status, w.skipped, 1, false),
            "47 frames: 30 decoded (26 from node 1, 4 commands to it); skipped: 3 error "
            "frames, 3 with 29-bit ids, 2 CAN FD, 2 remote, 6 of other nodes (node 2: 6), 1 of "
            "unknown messages, 0 of wrong length; the capture lost 2 frames");
  EXPECT_FALSE(silent_node_warning(w.status, 1, "shared_bus.log").has_value());
}

TEST(drive_monitor_capture, ForeignTrafficChangesNothingInTheDrivesValues) {
  const Watched clean = watch("monitor_sample.log", 1);
  const Watched shared = watch("shared_bus.log", 1);
  ASSERT_EQ(clean.error, "");
  ASSERT_EQ(shared.error, "");
  ASSERT_EQ(shared.rows.size(), clean.rows.size());
  ASSERT_EQ(clean.rows.size(), 5u);
  constexpr int64_t kOffset_us = 1'700'000'000'000'000;  // shared_bus.log's clock starts there
  for (std::size_t i = 0; i < clean.rows.size(); ++i) {
    EXPECT_EQ(shared.row_time_us[i] - clean.row_time_us[i], kOffset_us) << i;
    TelemetryRow a = clean.rows[i];
    TelemetryRow b = shared.rows[i];
    a.time_s = b.time_s = 0.0;  // compared exactly above, in microseconds
    EXPECT_EQ(csv_row(a), csv_row(b)) << i;
  }
  EXPECT_EQ(shared.status.heartbeat.count, clean.status.heartbeat.count);
  EXPECT_EQ(shared.status.heartbeat.counter, clean.status.heartbeat.counter);
  EXPECT_EQ(shared.status.ack.count, clean.status.ack.count);
  EXPECT_EQ(shared.status.ack.counter, clean.status.ack.counter);
  EXPECT_EQ(shared.status.ack.result, clean.status.ack.result);
  EXPECT_EQ(shared.status.state_change.count, clean.status.state_change.count);
}

TEST(drive_monitor_capture, WarnsWhenTheWatchedNodeSentNothing) {
  const Watched w = watch("node2_only.log", 1);
  ASSERT_EQ(w.error, "");
  EXPECT_EQ(frames_from_node(w.status.frames), 0u);
  EXPECT_EQ(w.skipped.error, 1u);
  EXPECT_EQ(w.status.frames.other_node_frames[2], 7u);
  const auto warning = silent_node_warning(w.status, 1, "node2_only.log");
  ASSERT_TRUE(warning.has_value());
  EXPECT_EQ(*warning,
            "warning: no frame from node 1 on node2_only.log; heard only other nodes (node 2: "
            "7): is --node right?");
  // The same log watched for node 2 is a good capture of node 2.
  const Watched node2 = watch("node2_only.log", 2);
  EXPECT_EQ(frames_from_node(node2.status.frames), 6u);
  EXPECT_FALSE(silent_node_warning(node2.status, 2, "node2_only.log").has_value());
}

TEST(drive_monitor_capture, CommandsToASilentNodeDoNotCountAsHearingIt) {
  DriveMonitor monitor(1);
  monitor.feed(0.0, protocol::encode_frame(1, protocol::MessageId::enable, {}));
  monitor.feed(0.1, protocol::encode_frame(1, protocol::MessageId::enable, {}));
  ASSERT_EQ(monitor.status().frames.commands, 2u);
  const auto warning = silent_node_warning(monitor.status(), 1, "can0");
  ASSERT_TRUE(warning.has_value());
  EXPECT_EQ(*warning,
            "warning: no frame from node 1 on can0 (2 commands to it); no other node either");
}

TEST(drive_monitor_capture, LiveSummaryCountsWhatTheInterfaceDropped) {
  DriveMonitor monitor(1);
  monitor.feed(0.0, protocol::encode_frame(3, protocol::MessageId::heartbeat, {}));
  SkippedFrames skipped;
  skipped.error = 2;        // the interface's error frames
  skipped.unsupported = 5;  // 29-bit or remote, not told apart
  EXPECT_EQ(summary_line(monitor.status(), skipped, 1, true),
            "8 frames: 0 decoded (0 from node 1, 0 commands to it); skipped: 2 error frames, 5 "
            "with 29-bit ids or remote, 1 of other nodes (node 3: 1), 0 of unknown messages, 0 "
            "of wrong length");
}

}  // namespace
}  // namespace imd::monitor
