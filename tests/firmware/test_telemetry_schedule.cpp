// The telemetry's schedule: each cyclic frame at its rate, and no tick carrying more than the
// fast sample's three frames or one other cyclic frame (a frame costs the MCU's tick hundreds
// of instructions; docs/performance-tick.md, "The whole tick, and the telemetry").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "fakes.hpp"
#include "firmware/protocol/frame_codec.hpp"
#include "firmware/telemetry.hpp"

namespace imd::firmware {
namespace {

using protocol::MessageId;

constexpr uint8_t kNode = 5;

MessageId id_of(const hal::CanFrame& f) {
  return static_cast<MessageId>(f.id - protocol::can_id(kNode, MessageId{}));
}

struct Sent {
  std::map<MessageId, int> count;
  std::map<MessageId, uint64_t> first_tick;
  int most_frames_a_tick = 0, most_other_frames_a_tick = 0;
  bool sample_split = false;  ///< a fast sample's frames on different ticks
};

/// `seconds` of ticks at `period_ns` with fast telemetry at `rate_Hz`.
Sent run(uint32_t period_ns, int rate_Hz, double seconds) {
  Telemetry telemetry(kNode, period_ns, rate_Hz);
  test::FakeCan can;
  TickRecord<float> record;
  DriveStatus status;
  StateMachine machine;
  ExecutionStats execution;
  Sent r;
  const auto ticks = uint64_t(seconds * 1e9 / period_ns + 0.5);
  for (uint64_t k = 0; k < ticks; ++k) {
    can.sent.clear();
    telemetry.publish(k, can, record, status, machine, execution, 80000);
    int fast = 0, other = 0;
    for (const hal::CanFrame& f : can.sent) {
      const MessageId id = id_of(f);
      if (r.count[id]++ == 0) r.first_tick[id] = k;
      const bool is_fast = id == MessageId::telemetry_speed_flux ||
                           id == MessageId::telemetry_current || id == MessageId::telemetry_voltage;
      (is_fast ? fast : other)++;
    }
    // The version goes before the first frame of a start, whatever that frame is.
    if (k == 0) --other;
    r.sample_split = r.sample_split || (fast != 0 && fast != 3);
    r.most_frames_a_tick = std::max(r.most_frames_a_tick, fast + other);
    r.most_other_frames_a_tick = std::max(r.most_other_frames_a_tick, other);
  }
  return r;
}

/// The fast samples in `seconds`: one every round(1 s / rate / period) ticks (at least one),
/// from tick 1 (Telemetry::set_rate_Hz).
double ticks_per_sample(uint32_t period_ns, int rate_Hz) {
  return std::max(1.0, std::round(1e9 / rate_Hz / double(period_ns)));
}
double samples_in(uint32_t period_ns, int rate_Hz, double seconds) {
  return seconds * 1e9 / double(period_ns) / ticks_per_sample(period_ns, rate_Hz);
}

void expect_every_frame(const Sent& r, uint32_t period_ns, int rate_Hz) {
  // 2 s: the 10 Hz frames 20 times; the version at the start and with the 10th and 20th
  // heartbeat; the fast samples within one of their count.
  EXPECT_EQ(r.count.at(MessageId::heartbeat), 20);
  EXPECT_EQ(r.count.at(MessageId::timing), 20);
  EXPECT_EQ(r.count.at(MessageId::stage_timing_1), 20);
  EXPECT_EQ(r.count.at(MessageId::stage_timing_2), 20);
  EXPECT_EQ(r.count.at(MessageId::version), 3);
  const int samples = r.count.at(MessageId::telemetry_voltage);
  EXPECT_NEAR(samples, samples_in(period_ns, rate_Hz, 2.0), 1.0);
  EXPECT_EQ(r.count.at(MessageId::telemetry_speed_flux), samples);
  EXPECT_EQ(r.count.at(MessageId::telemetry_current), samples);
  EXPECT_FALSE(r.sample_split);
  // The start: the version, then the heartbeat at tick 0, the first sample at tick 1.
  EXPECT_EQ(r.first_tick.at(MessageId::heartbeat), 0u);
  EXPECT_EQ(r.first_tick.at(MessageId::telemetry_voltage), 1u);
}

TEST(TelemetrySchedule, EachFrameAtItsRateAndOneCyclicFrameATick) {
  for (const uint32_t period_ns : {100'000u, 50'000u, 1'000'000u}) {  // 10, 20 and 1 kHz
    for (const int rate_Hz : {10, 100, 333, 1000}) {
      SCOPED_TRACE(::testing::Message() << period_ns << " ns, " << rate_Hz << " Hz");
      const Sent r = run(period_ns, rate_Hz, 2.0);
      expect_every_frame(r, period_ns, rate_Hz);
      EXPECT_LE(r.most_other_frames_a_tick, 1);
      // A sample's three frames, and one more only where a sample takes every tick.
      EXPECT_LE(r.most_frames_a_tick, ticks_per_sample(period_ns, rate_Hz) > 1.0 ? 3 : 4);
    }
  }
}

TEST(TelemetrySchedule, ASlowLoopSendsEveryFrameAtOnce) {
  // 10 ms and 6.25 ms periods (10 and 16 ticks per 100 ms): too few ticks to spread the frames
  // without losing one; every frame still goes out at its rate.
  for (const uint32_t period_ns : {10'000'000u, 6'250'000u}) {
    for (const int rate_Hz : {10, 50, 100}) {
      SCOPED_TRACE(::testing::Message() << period_ns << " ns, " << rate_Hz << " Hz");
      expect_every_frame(run(period_ns, rate_Hz, 2.0), period_ns, rate_Hz);
    }
  }
}

}  // namespace
}  // namespace imd::firmware
