// drive_monitor send --repeat-hz: the schedule and tally of a repeated send, against fake
// times and frames, and against a drive's own command decoder (no CAN on the test host).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <deque>
#include <set>
#include <string>
#include <utility>

#include "firmware/protocol/commands.hpp"
#include "firmware/protocol/e2e.hpp"
#include "firmware/protocol/frame_codec.hpp"
#include "tools/drive_monitor/monitor.hpp"
#include "tools/drive_monitor/repeat_send.hpp"
#include "tools/drive_monitor/send_command.hpp"

namespace imd::monitor {
namespace {

using protocol::CommandKind;
using protocol::CommandResult;
using protocol::encode_frame;
using protocol::MessageId;

constexpr uint8_t kNode = 1;

// --- send --repeat-hz: CommandRepeater

using namespace std::chrono_literals;

const SteadyTime kStart = SteadyTime{} + 1000s;  // any steady_clock time will do
const protocol::Command kSpeed30{CommandKind::set_speed, 30.0f};

uint8_t counter_of(const hal::CanFrame& frame) {
  return protocol::e2e_counter(frame.data);
}

/// The drive's answer to `command`, as Telemetry::acknowledge builds it.
hal::CanFrame ack_of(const hal::CanFrame& command, CommandResult result, uint8_t node = kNode) {
  return encode_frame(
      node, MessageId::command_ack,
      {float(protocol::message_of(command.id)), float(counter_of(command)), float(result), 0.0f});
}

TEST(drive_monitor_repeat, CountsTheSlotsOfAPlan) {
  EXPECT_EQ(repeat_slot_count(20.0, 3.0), 60u);  // 0, 0.05, ..., 2.95 s
  EXPECT_EQ(repeat_slot_count(10.0, 0.3), 3u);   // 3.0000000000000004: no slot at 0.3 s
  EXPECT_EQ(repeat_slot_count(3.0, 1.0), 3u);    // 0, 1/3, 2/3 s
  EXPECT_EQ(repeat_slot_count(3.0, 0.5), 2u);    // 0, 1/3 s
  EXPECT_EQ(repeat_slot_count(1.0, 0.001), 1u);  // the first frame goes out at once
  EXPECT_EQ(repeat_slot_count(0.1, 25.0), 3u);   // 0, 10, 20 s
  EXPECT_EQ(repeat_slot_count(1000.0, 1e7), 10'000'000'000u);
}

TEST(drive_monitor_repeat, SendsOnAbsoluteDeadlinesWithConsecutiveCounters) {
  CommandRepeater repeater(kNode, kSpeed30, 14, {20.0, 3.0, 0.5}, kStart);
  protocol::CommandEncoder reference(kNode, 14);
  EXPECT_EQ(repeater.tally().planned, 60u);
  for (uint64_t k = 0; k < 60; ++k) {
    const SteadyTime due = kStart + k * 50ms;
    ASSERT_EQ(repeater.slot_time(k), due) << k;
    ASSERT_EQ(repeater.next_event(), due) << k;  // the last frame's ack is not due before it
    ASSERT_FALSE(repeater.frame_due(due - 1ns)) << k;
    const auto frame = repeater.frame_due(due);
    ASSERT_TRUE(frame) << k;
    EXPECT_EQ(counter_of(*frame), (14 + k) & 0x0F) << k;  // wraps 15 -> 0
    const hal::CanFrame expected = reference.encode(kSpeed30);
    EXPECT_EQ(frame->id, expected.id);
    EXPECT_EQ(frame->data, expected.data) << k;  // same payload, next counter, its CRC
    repeater.sent(due, true);
    repeater.receive(due + 1ms, ack_of(*frame, CommandResult::accepted));
  }
  EXPECT_FALSE(repeater.frame_due(kStart + 1h));
  EXPECT_TRUE(repeater.finished(kStart + 3s));
  EXPECT_EQ(repeater.next_event(), SteadyTime::max());
  EXPECT_EQ(verdict(repeater.tally()), RepeatVerdict::all_accepted);
  EXPECT_EQ(repeat_summary(repeater.tally(), kSpeed30, 20.0),
            "sent 60 set_speed 30.000 rad/s frames at 20 Hz: 60 accepted, 0 rejected, "
            "0 unanswered");
}

TEST(drive_monitor_repeat, DeadlinesDoNotDriftWhenThePeriodIsNotAWholeNumberOfTicks) {
  // 1/3 s is 333333333.33 ns: adding a rounded period would lose 1/3 ns per frame.
  CommandRepeater repeater(kNode, kSpeed30, 0, {3.0, 1e7, 0.5}, kStart);
  EXPECT_EQ(repeater.slot_time(1), kStart + 333'333'333ns);
  EXPECT_EQ(repeater.slot_time(3), kStart + 1s);
  EXPECT_EQ(repeater.slot_time(3'000'000), kStart + 1'000'000s);
  EXPECT_EQ(repeater.slot_time(29'999'997), kStart + 9'999'999s);  // near the longest --for-s
}

TEST(drive_monitor_repeat, SkipsSlotsItWokeUpTooLateForInsteadOfSendingABurst) {
  CommandRepeater repeater(kNode, kSpeed30, 5, {10.0, 1.0, 0.5}, kStart);
  auto frame = repeater.frame_due(kStart);
  ASSERT_TRUE(frame);
  repeater.sent(kStart, true);
  frame = repeater.frame_due(kStart + 350ms);  // slots at 0.1 and 0.2 s were missed
  ASSERT_TRUE(frame);
  EXPECT_EQ(counter_of(*frame), 6);  // a skipped slot uses no counter
  repeater.sent(kStart + 350ms, true);
  EXPECT_EQ(repeater.tally().skipped, 2u);
  EXPECT_FALSE(repeater.frame_due(kStart + 350ms));
  EXPECT_EQ(repeater.next_event(), kStart + 400ms);
  ASSERT_TRUE(repeater.frame_due(kStart + 100s));  // the last slot, 0.9 s
  repeater.sent(kStart + 100s, true);
  EXPECT_FALSE(repeater.frame_due(kStart + 100s));
  const RepeatTally& t = repeater.tally();
  EXPECT_EQ(t.sent, 3u);
  EXPECT_EQ(t.skipped, 7u);
  EXPECT_EQ(t.sent + t.skipped, t.planned);
  EXPECT_NE(repeat_summary(t, kSpeed30, 10.0).find(", 7 skipped (the tool woke up late)"),
            std::string::npos);
}

TEST(drive_monitor_repeat, MatchesAcksAsTheyComeAndIgnoresOthers) {
  CommandRepeater repeater(kNode, kSpeed30, 0, {1000.0, 0.005, 0.5}, kStart);
  std::vector<hal::CanFrame> frames;
  for (SteadyTime t = kStart; t < kStart + 5ms; t += 1ms) {
    const auto frame = repeater.frame_due(t);
    ASSERT_TRUE(frame);
    repeater.sent(t, true);
    frames.push_back(*frame);
  }
  EXPECT_FALSE(repeater.finished(kStart + 5ms));  // all five still wait: no stop-and-wait
  const SteadyTime t = kStart + 6ms;
  const hal::CanFrame other_command = encode_frame(
      kNode, MessageId::command_ack, {float(MessageId::enable), float(counter_of(frames[0]))});
  repeater.receive(t, other_command);
  repeater.receive(t, ack_of(frames[0], CommandResult::accepted, 2));  // another node
  repeater.receive(
      t, encode_frame(kNode, MessageId::heartbeat, {3.0f, 0.0f, 0.0f, 7.0f, 4.0f}));  // not an ack
  for (auto it = frames.rbegin(); it != frames.rend(); ++it) {  // in any order
    repeater.receive(t, ack_of(*it, CommandResult::accepted));
  }
  repeater.receive(t, ack_of(frames[2], CommandResult::bad_crc));  // a duplicate: already counted
  EXPECT_TRUE(repeater.finished(t));
  EXPECT_EQ(repeater.tally().accepted, 5u);
  EXPECT_EQ(repeater.tally().rejected_total(), 0u);
  EXPECT_EQ(verdict(repeater.tally()), RepeatVerdict::all_accepted);
}

TEST(drive_monitor_repeat, TalliesRejectionsByReason) {
  CommandRepeater repeater(kNode, kSpeed30, 0, {100.0, 0.04, 0.5}, kStart);
  const CommandResult results[] = {CommandResult::not_allowed, CommandResult::accepted,
                                   CommandResult::out_of_range, CommandResult::not_allowed};
  SteadyTime t = kStart;
  for (const CommandResult result : results) {
    const auto frame = repeater.frame_due(t);
    ASSERT_TRUE(frame);
    repeater.sent(t, true);
    repeater.receive(t + 1ms, ack_of(*frame, result));
    t += 10ms;
  }
  EXPECT_TRUE(repeater.finished(t));
  EXPECT_EQ(repeater.tally().rejected_total(), 3u);
  EXPECT_EQ(repeater.tally().rejected[std::size_t(CommandResult::not_allowed)], 2u);
  EXPECT_EQ(verdict(repeater.tally()), RepeatVerdict::rejected);
  EXPECT_EQ(repeat_summary(repeater.tally(), kSpeed30, 100.0),
            "sent 4 set_speed 30.000 rad/s frames at 100 Hz: 1 accepted, 3 rejected "
            "(1 out_of_range, 2 not_allowed), 0 unanswered");
}

TEST(drive_monitor_repeat, GivesUpOnAnAckAfterTheTimeout) {
  CommandRepeater repeater(kNode, kSpeed30, 0, {1.0, 1.0, 0.25}, kStart);
  const auto frame = repeater.frame_due(kStart);
  ASSERT_TRUE(frame);
  repeater.sent(kStart, true);
  EXPECT_EQ(repeater.next_event(), kStart + 250ms);  // no slot left: the ack deadline
  EXPECT_FALSE(repeater.finished(kStart + 250ms - 1ns));
  EXPECT_TRUE(repeater.finished(kStart + 250ms));
  repeater.receive(kStart + 300ms, ack_of(*frame, CommandResult::accepted));  // too late
  EXPECT_EQ(repeater.tally().unanswered, 1u);
  EXPECT_EQ(repeater.tally().accepted, 0u);
  EXPECT_EQ(verdict(repeater.tally()), RepeatVerdict::not_all_accepted);
  EXPECT_EQ(repeat_summary(repeater.tally(), kSpeed30, 1.0),
            "sent 1 set_speed 30.000 rad/s frames at 1 Hz: 0 accepted, 0 rejected, 1 unanswered");
}

TEST(drive_monitor_repeat, GivesUpOnAnAckWhenItsCounterComesRound) {
  CommandRepeater repeater(kNode, kSpeed30, 3, {1000.0, 0.017, 10.0}, kStart);
  std::vector<hal::CanFrame> frames;
  for (int k = 0; k < 17; ++k) {
    const SteadyTime t = kStart + k * 1ms;
    const auto frame = repeater.frame_due(t);
    ASSERT_TRUE(frame);
    repeater.sent(t, true);
    frames.push_back(*frame);
  }
  EXPECT_EQ(counter_of(frames[16]), counter_of(frames[0]));
  EXPECT_EQ(repeater.tally().unanswered, 1u);  // frame 0: its ack would now match frame 16
  repeater.receive(kStart + 17ms, ack_of(frames[16], CommandResult::accepted));
  EXPECT_EQ(repeater.tally().accepted, 1u);
}

TEST(drive_monitor_repeat, ReusesTheCounterOfAFrameTheSocketRefused) {
  CommandRepeater repeater(kNode, kSpeed30, 9, {10.0, 0.3, 0.5}, kStart);
  ASSERT_TRUE(repeater.frame_due(kStart));
  repeater.sent(kStart, false);  // transmit queue full
  const auto frame = repeater.frame_due(kStart + 100ms);
  ASSERT_TRUE(frame);
  EXPECT_EQ(counter_of(*frame), 9);  // the refused frame never reached the bus
  repeater.sent(kStart + 100ms, true);
  repeater.receive(kStart + 101ms, ack_of(*frame, CommandResult::accepted));
  const auto last = repeater.frame_due(kStart + 200ms);
  ASSERT_TRUE(last);
  repeater.sent(kStart + 200ms, true);
  repeater.receive(kStart + 201ms, ack_of(*last, CommandResult::accepted));
  EXPECT_TRUE(repeater.finished(kStart + 201ms));
  EXPECT_EQ(repeater.tally().send_failures, 1u);
  EXPECT_EQ(verdict(repeater.tally()), RepeatVerdict::not_all_accepted);  // one slot went unsent
  EXPECT_EQ(repeat_summary(repeater.tally(), kSpeed30, 10.0),
            "sent 2 set_speed 30.000 rad/s frames at 10 Hz: 2 accepted, 0 rejected, "
            "0 unanswered, 1 not sent (transmit queue full or interface down)");
}

TEST(drive_monitor_repeat, StopEndsTheRepetitionButStillMatchesTheAcksInFlight) {
  CommandRepeater repeater(kNode, kSpeed30, 0, {20.0, 3.0, 0.5}, kStart);
  std::vector<hal::CanFrame> frames;
  for (const SteadyTime t : {kStart, kStart + 50ms}) {
    frames.push_back(*repeater.frame_due(t));
    repeater.sent(t, true);
  }
  repeater.stop(kStart + 70ms);  // SIGINT
  EXPECT_FALSE(repeater.frame_due(kStart + 100ms));
  EXPECT_FALSE(repeater.finished(kStart + 100ms));
  EXPECT_EQ(repeater.next_event(), kStart + 500ms);  // the first frame's ack deadline
  for (const hal::CanFrame& f : frames) {
    repeater.receive(kStart + 101ms, ack_of(f, CommandResult::accepted));
  }
  EXPECT_TRUE(repeater.finished(kStart + 101ms));
  EXPECT_EQ(verdict(repeater.tally()), RepeatVerdict::all_accepted);
  EXPECT_EQ(repeat_summary(repeater.tally(), kSpeed30, 20.0),
            "sent 2 set_speed 30.000 rad/s frames at 20 Hz: 2 accepted, 0 rejected, "
            "0 unanswered; stopped after 0.070 s");
}

TEST(drive_monitor_repeat, NothingSentIsNotSuccess) {
  CommandRepeater repeater(kNode, kSpeed30, 0, {20.0, 3.0, 0.5}, kStart);
  repeater.stop(kStart);  // a signal before the first frame
  EXPECT_TRUE(repeater.finished(kStart));
  EXPECT_EQ(verdict(repeater.tally()), RepeatVerdict::not_all_accepted);
}

/// The host side of a bus with a drive's command decoder at the other end: the decoder sees
/// each frame when sent (unless it is lost), and its ack reaches the host `ack_delay` later.
struct SimulatedBus {
  protocol::CommandDecoder decoder{kNode, protocol::CommandLimits{}};
  std::chrono::nanoseconds ack_delay = 3ms;
  std::set<uint64_t> lost;  ///< indices of frames that never reach the drive
  std::deque<std::pair<SteadyTime, hal::CanFrame>> to_host;
  std::vector<CommandResult> results;  ///< the drive's verdict on each frame it got, in order

  /// Steps the host loop in 0.1 ms steps until the repeater is done.
  void run(CommandRepeater& repeater) {
    uint64_t frames = 0;
    for (SteadyTime now = kStart; !repeater.finished(now); now += 100us) {
      ASSERT_LT(now, kStart + 1h) << "did not finish";
      while (!to_host.empty() && to_host.front().first <= now) {
        repeater.receive(now, to_host.front().second);
        to_host.pop_front();
      }
      const auto frame = repeater.frame_due(now);
      if (!frame) continue;
      repeater.sent(now, true);
      if (lost.count(frames++) > 0) continue;
      const protocol::Decoded d = decoder.decode(*frame);
      results.push_back(d.result);
      to_host.emplace_back(now + ack_delay, encode_frame(kNode, MessageId::command_ack,
                                                         {float(d.message_id), float(d.counter),
                                                          float(d.result), 0.0f}));
    }
  }
};

TEST(drive_monitor_repeat, TheDrivesDecoderAcceptsEveryFrameAtTheHighestRate) {
  for (const protocol::Command command :
       {kSpeed30, protocol::Command{CommandKind::emergency_stop}}) {
    SimulatedBus bus;
    // The drive already has a counter reference, from another host's frame: the repeater starts
    // one past it, as send does from the heartbeat.
    protocol::CommandEncoder other_host(kNode, 11);
    ASSERT_EQ(bus.decoder.decode(other_host.encode(kSpeed30)).result, CommandResult::accepted);
    CommandRepeater repeater(kNode, command, 12, {kMaxRepeatRate_Hz, 0.2, 0.5}, kStart);
    bus.run(repeater);
    const RepeatTally& t = repeater.tally();
    EXPECT_EQ(t.sent, 200u) << describe_command(command);
    EXPECT_EQ(t.accepted, 200u) << describe_command(command);
    EXPECT_EQ(bus.decoder.rejected_total(), 0u) << describe_command(command);
    EXPECT_EQ(verdict(t), RepeatVerdict::all_accepted) << repeat_summary(t, command, 1000.0);
  }
}

TEST(drive_monitor_repeat, CountersComeBackIntoTheDrivesWindowAfterTooManyLostFrames) {
  SimulatedBus bus;
  bus.lost = {10, 11, 12};  // three in a row: frame 13 is 4 ahead of the drive's reference
  CommandRepeater repeater(kNode, kSpeed30, 0, {kMaxRepeatRate_Hz, 0.3, 0.5}, kStart);
  bus.run(repeater);
  const RepeatTally& t = repeater.tally();
  const std::string summary = repeat_summary(t, kSpeed30, 1000.0);
  // The reference stays at frame 9's counter: frames 13..24 are 4..15 ahead (stale), frame 25
  // repeats it, frame 26 is 1 ahead and accepted, and so is every frame after it.
  EXPECT_EQ(t.unanswered, 3u) << summary;
  EXPECT_EQ(t.rejected[std::size_t(CommandResult::stale_counter)], 12u) << summary;
  EXPECT_EQ(t.rejected[std::size_t(CommandResult::repeated_counter)], 1u) << summary;
  EXPECT_EQ(t.accepted, t.sent - 3 - 13) << summary;
  ASSERT_EQ(bus.results.size(), t.sent - 3);
  for (std::size_t i = 26 - 3; i < bus.results.size(); ++i) {
    EXPECT_EQ(bus.results[i], CommandResult::accepted) << i;
  }
  EXPECT_EQ(verdict(t), RepeatVerdict::rejected);
  EXPECT_EQ(summary,
            "sent 300 set_speed 30.000 rad/s frames at 1000 Hz: 284 accepted, 13 rejected "
            "(1 repeated_counter, 12 stale_counter), 3 unanswered");
}

// --- send set-speed --enable: the enable leads, the speed follows at once

const protocol::Command kEnable{CommandKind::enable};

TEST(drive_monitor_repeat, AnEnableLeadsAndTheSpeedFollowsAtOnceWithTheNextCounter) {
  CommandRepeater repeater(kNode, kSpeed30, 5, {10.0, 0.2, 0.5}, kStart, kEnable);
  EXPECT_EQ(repeater.next_event(), kStart);
  const auto enable = repeater.frame_due(kStart);
  ASSERT_TRUE(enable);
  EXPECT_EQ(enable->id, protocol::can_id(kNode, MessageId::enable));
  EXPECT_EQ(counter_of(*enable), 5);
  repeater.sent(kStart, true);
  const auto speed = repeater.frame_due(kStart);  // no wait for the enable's ack
  ASSERT_TRUE(speed);
  EXPECT_EQ(speed->id, protocol::can_id(kNode, MessageId::set_speed));
  EXPECT_EQ(counter_of(*speed), 6);
  repeater.sent(kStart, true);
  repeater.receive(kStart + 1ms, ack_of(*enable, CommandResult::accepted));
  repeater.receive(kStart + 1ms, ack_of(*speed, CommandResult::accepted));
  const auto second = repeater.frame_due(kStart + 100ms);
  ASSERT_TRUE(second);
  EXPECT_EQ(counter_of(*second), 7);
  repeater.sent(kStart + 100ms, true);
  EXPECT_FALSE(repeater.finished(kStart + 100ms));
  repeater.receive(kStart + 101ms, ack_of(*second, CommandResult::accepted));
  EXPECT_TRUE(repeater.finished(kStart + 101ms));
  EXPECT_EQ(verdict(repeater.tally()), RepeatVerdict::all_accepted);
  EXPECT_EQ(repeat_summary(repeater.tally(), kSpeed30, 10.0),
            "enable: accepted; sent 2 set_speed 30.000 rad/s frames at 10 Hz: 2 accepted, 0 "
            "rejected, 0 unanswered");
}

TEST(drive_monitor_repeat, ARefusedEnableStopsTheRepetition) {
  CommandRepeater repeater(kNode, kSpeed30, 0, {10.0, 60.0, 0.5}, kStart, kEnable);
  const auto enable = repeater.frame_due(kStart);
  repeater.sent(kStart, true);
  const auto speed = repeater.frame_due(kStart);
  repeater.sent(kStart, true);
  repeater.receive(kStart + 2ms, ack_of(*enable, CommandResult::not_allowed));  // faulted
  repeater.receive(kStart + 2ms, ack_of(*speed, CommandResult::accepted));
  EXPECT_FALSE(repeater.frame_due(kStart + 100ms));
  EXPECT_TRUE(repeater.finished(kStart + 2ms));
  EXPECT_EQ(verdict(repeater.tally()), RepeatVerdict::rejected);
  EXPECT_EQ(repeat_summary(repeater.tally(), kSpeed30, 10.0),
            "enable: not_allowed; sent 1 set_speed 30.000 rad/s frames at 10 Hz: 1 accepted, 0 "
            "rejected, 0 unanswered; stopped after 0.002 s");
  // The socket refused the enable: nothing follows it.
  CommandRepeater refused(kNode, kSpeed30, 0, {10.0, 60.0, 0.5}, kStart, kEnable);
  ASSERT_TRUE(refused.frame_due(kStart));
  refused.sent(kStart, false);
  EXPECT_FALSE(refused.frame_due(kStart));
  EXPECT_TRUE(refused.finished(kStart));
  EXPECT_EQ(verdict(refused.tally()), RepeatVerdict::not_all_accepted);
  // An enable without an ack: the speed goes on (the drive may have obeyed), the exit is not 0.
  CommandRepeater silent(kNode, kSpeed30, 0, {10.0, 0.1, 0.5}, kStart, kEnable);
  ASSERT_TRUE(silent.frame_due(kStart));
  silent.sent(kStart, true);
  const auto only = silent.frame_due(kStart);
  silent.sent(kStart, true);
  silent.receive(kStart + 1ms, ack_of(*only, CommandResult::accepted));
  EXPECT_TRUE(silent.finished(kStart + 500ms));
  EXPECT_EQ(verdict(silent.tally()), RepeatVerdict::not_all_accepted);
  EXPECT_TRUE(silent.tally().lead->unanswered);
}

TEST(drive_monitor_repeat, TheDrivesDecoderAcceptsTheEnableAndEverySpeedFrame) {
  SimulatedBus bus;
  CommandRepeater repeater(kNode, kSpeed30, 4, {20.0, 1.0, 0.5}, kStart, kEnable);
  bus.run(repeater);
  ASSERT_EQ(bus.results.size(), 21u);  // the enable, then 20 speed frames
  for (const CommandResult r : bus.results) EXPECT_EQ(r, CommandResult::accepted);
  EXPECT_EQ(verdict(repeater.tally()), RepeatVerdict::all_accepted)
      << repeat_summary(repeater.tally(), kSpeed30, 20.0);
}

}  // namespace
}  // namespace imd::monitor
