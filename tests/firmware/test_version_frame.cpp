// The version frame: the drive's first frame after every start, then once a second (so that a
// host joining later learns it), carrying the protocol version and the firmware's version and
// git commit exactly (the 32-bit hash as raw bits).
#include <gtest/gtest.h>
#include <imd_version.hpp>

#include <vector>

#include "firmware/drive.hpp"
#include "firmware/protocol/frame_codec.hpp"
#include "hal_sim/sim_board.hpp"
#include "test_motors.hpp"

namespace imd::firmware {
namespace {

using protocol::MessageId;

int64_t raw(const hal::CanFrame& frame, const char* name) {
  const protocol::Message& m = protocol::message(MessageId::version);
  const int index = protocol::find_signal(m, name);
  EXPECT_GE(index, 0) << name;
  return protocol::get_raw(frame.data, m.signals[static_cast<std::size_t>(index)]);
}

/// The frames a freshly started drive (node 3) sends in its first `ticks` ticks.
std::vector<hal::CanFrame> frames_after_start(int ticks) {
  sim::SimBoard board(test::test_motors()[0].parameters, {});
  DriveConfig config;
  config.node_id = 3;
  config.protection.tick_budget_ns = 0;  // wall-clock time on a shared host is not the MCU's
  Drive<double> drive(test::test_motors()[0].parameters, config,
                      {board.pwm(), board.encoder(), board.adc(), board.timer(), &board.can()});
  board.timer().start(drive);
  std::vector<hal::CanFrame> sent;
  for (int k = 0; k < ticks; ++k) {
    board.run_tick();
    for (hal::CanFrame f; board.can_side().take_sent(f);) sent.push_back(f);
  }
  return sent;
}

TEST(VersionFrame, IsTheFirstFrameAfterStartWithTheBuildsVersion) {
  const std::vector<hal::CanFrame> sent = frames_after_start(1);
  ASSERT_GE(sent.size(), 2u);  // the version, then the heartbeat due at tick 0
  const hal::CanFrame& v = sent[0];
  ASSERT_EQ(v.id, protocol::can_id(3, MessageId::version));
  EXPECT_EQ(v.length, protocol::message(MessageId::version).length);
  EXPECT_EQ(raw(v, "protocol_version"), protocol::kProtocolVersion);
  EXPECT_EQ(raw(v, "firmware_major"), imd::version::kMajor);
  EXPECT_EQ(raw(v, "firmware_minor"), imd::version::kMinor);
  EXPECT_EQ(raw(v, "firmware_patch"), imd::version::kPatch);
  EXPECT_EQ(raw(v, "dirty"), imd::version::kDirty ? 1 : 0);
  EXPECT_EQ(raw(v, "git_hash"), int64_t{imd::version::kGitHash});
  EXPECT_EQ(sent[1].id, protocol::can_id(3, MessageId::heartbeat));
}

TEST(VersionFrame, IsSentFirstAtEachStartThenOnceASecond) {
  // 2.05 s at 10 kHz: the frame at start, then with the 10th and 20th heartbeat (1 s, 2 s).
  constexpr int kTicks = 20500;
  const protocol::Message& heartbeat = protocol::message(MessageId::heartbeat);
  const int per_version = protocol::message(MessageId::version).period_ms / heartbeat.period_ms;
  ASSERT_EQ(per_version, 10);
  for (int start = 0; start < 2; ++start) {  // a second start (a reset) sends it again
    const std::vector<hal::CanFrame> sent = frames_after_start(kTicks);
    std::vector<int> heartbeats_before;  // how many heartbeats preceded each version frame
    int heartbeats = 0;
    for (const hal::CanFrame& f : sent) {
      if (f.id == protocol::can_id(3, MessageId::heartbeat)) ++heartbeats;
      if (f.id == protocol::can_id(3, MessageId::version)) heartbeats_before.push_back(heartbeats);
    }
    EXPECT_EQ(sent.front().id, protocol::can_id(3, MessageId::version)) << "start " << start;
    EXPECT_EQ(heartbeats_before, (std::vector<int>{0, per_version, 2 * per_version}))
        << "start " << start;
  }
}

}  // namespace
}  // namespace imd::firmware
