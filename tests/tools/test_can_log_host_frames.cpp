// drive_sim --can-log writes the bus as candump -L -x on the host's interface sees it: the
// scenario's commands transmitted (T), the drive's frames received (R). This checks the run's
// two frame callbacks that it is built on, on the CAN scenario: every scripted frame is logged
// once, at the time of the tick it is delivered before, each line in order and readable back.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "firmware/protocol/messages.hpp"
#include "hal_sim/drive/scenario_run.hpp"
#include "hal_sim/drive/scripted_commands.hpp"
#include "hal_sim/scenario.hpp"
#include "tools/can_log/candump_log.hpp"

namespace imd::can_log {
namespace {

namespace protocol = firmware::protocol;

struct Logged {
  double t_s;
  hal::CanFrame frame;
  Direction direction;
};

TEST(can_log_host_frames, LogsTheScriptsFramesTransmittedAndTheDrivesReceived) {
  // 0.3 s holds the enable (0.05 s) and five set_speed frames (0.06 s, every 0.05 s).
  const sim::Scenario s =
      sim::load_scenario(std::string(IMD_SOURCE_DIR) + "/hal_sim/scenarios/seed000_can.toml",
                         {"simulation.duration_s=0.3", "metrics.settle_s=0.2"});
  std::vector<Logged> log;
  sim::RunCallbacks callbacks;
  callbacks.can_frame = [&](double t_s, const hal::CanFrame& f) {
    log.push_back({t_s, f, Direction::received});
  };
  callbacks.host_frame = [&](double t_s, const hal::CanFrame& f) {
    log.push_back({t_s, f, Direction::transmitted});
  };
  const sim::Summary summary = sim::run_scenario(s, callbacks);

  std::vector<sim::ScriptedFrame> expected;
  for (const sim::ScriptedFrame& f : sim::scripted_frames(s)) {
    if (f.tick < summary.ticks) expected.push_back(f);
  }
  ASSERT_EQ(expected.size(), 6u);
  std::size_t next_host = 0;
  double last_t_s = 0.0;
  std::size_t acks_after_commands = 0;
  for (std::size_t i = 0; i < log.size(); ++i) {
    const Logged& l = log[i];
    EXPECT_GE(l.t_s, last_t_s) << "line " << i << ": time goes back";
    last_t_s = l.t_s;
    const protocol::Message* m = protocol::find_message(protocol::message_of(l.frame.id));
    ASSERT_NE(m, nullptr) << "line " << i;
    EXPECT_EQ(protocol::node_of(l.frame.id), s.can_node_id) << "line " << i;
    if (l.direction == Direction::transmitted) {
      EXPECT_EQ(m->direction, protocol::Direction::host_to_drive) << m->name;
      ASSERT_LT(next_host, expected.size());
      const sim::ScriptedFrame& want = expected[next_host++];
      EXPECT_EQ(l.frame.id, want.frame.id);
      EXPECT_EQ(l.frame.data, want.frame.data);
      // Both are tick * sample period, computed the same way: exactly equal.
      EXPECT_EQ(l.t_s, double(want.tick) * s.sample_period_s) << m->name;
      // The drive answers within the tick the command is delivered before.
      for (std::size_t j = i + 1; j < log.size() && log[j].t_s == l.t_s; ++j) {
        if (protocol::message_of(log[j].frame.id) == uint8_t(protocol::MessageId::command_ack)) {
          ++acks_after_commands;
          break;
        }
      }
    } else {
      EXPECT_EQ(m->direction, protocol::Direction::drive_to_host) << m->name;
    }
    const ParseResult back = parse_log_line(format_log_line(l.t_s, "can0", l.frame, l.direction));
    ASSERT_TRUE(back.ok()) << back.error.message;
    EXPECT_EQ(back.line->direction, l.direction);
    EXPECT_EQ(classic_frame(back.line->frame)->data, l.frame.data);
  }
  EXPECT_EQ(next_host, expected.size());
  EXPECT_EQ(acks_after_commands, expected.size());
}

}  // namespace
}  // namespace imd::can_log
