// drive_monitor's library: decoding by the protocol table, telemetry row assembly and CSV text,
// the status table, the send command's local checks and answer matching (fake frames: no CAN
// on the test host). The repeated send: test_drive_monitor_repeat.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <set>
#include <string>
#include <utility>

#include "firmware/protocol/commands.hpp"
#include "firmware/protocol/e2e.hpp"
#include "firmware/protocol/frame_codec.hpp"
#include "tools/drive_monitor/monitor.hpp"
#include "tools/drive_monitor/send_command.hpp"
#include "tools/drive_monitor/status_table.hpp"

namespace imd::monitor {
namespace {

using protocol::CommandKind;
using protocol::CommandResult;
using protocol::encode_frame;
using protocol::MessageId;

constexpr uint8_t kNode = 1;

hal::CanFrame heartbeat(float state, float first_fault = 0.0f, float command_counter = 0.0f,
                        uint16_t fault_bits = 0) {
  hal::CanFrame frame =
      encode_frame(kNode, MessageId::heartbeat,
                   {state, first_fault, 7.0f, command_counter, 1.0f, 0.0f, 2.0f, 1.0f, 3.0f});
  protocol::set_fault_bits(frame.data, protocol::kHeartbeatFaultWordBit, fault_bits);
  return frame;
}
hal::CanFrame speed_flux(float speed_rad_s) {
  return encode_frame(kNode, MessageId::telemetry_speed_flux, {speed_rad_s, 100.0f, 0.81f, 0.8f});
}
hal::CanFrame current(float i_A) {
  return encode_frame(kNode, MessageId::telemetry_current, {i_A, -2.5f, 0.75f, 300.1f});
}
hal::CanFrame voltage(float sample) {
  return encode_frame(kNode, MessageId::telemetry_voltage, {12.3f, -45.6f, sample, 1.05f});
}

TEST(drive_monitor_decode, NamesEnumeratedValues) {
  const DecodedFrame d = decode_frame(heartbeat(3.0f, 2.0f), kNode);
  ASSERT_EQ(d.kind, FrameKind::decoded);
  ASSERT_EQ(d.signal_count, 27u);  // 12 of its own, one per fault code 1..15
  EXPECT_STREQ(d.signals[0].signal->name, "state");
  EXPECT_STREQ(d.signals[0].value_name, "running");
  EXPECT_STREQ(d.signals[1].value_name, "overcurrent");
  EXPECT_STREQ(d.signals[12].signal->name, "fault_adc_offset");
  EXPECT_STREQ(d.signals[26].signal->name, "fault_enable_input");
  EXPECT_EQ(describe(d),
            "heartbeat state=running first_fault=overcurrent counter=7 "
            "command_counter=0 controller=iol can_bus_off=0 rejected_commands=2 limited=voltage "
            "transitions=3 stop=none brake=0 reset_cause=power_on faults=none");
}

TEST(drive_monitor_decode, ReadsTheFaultBitsAsOneWord) {
  // Bits 2 and 10 of the word (overcurrent, encoder) are bits 10 and 18 of the frame.
  const hal::CanFrame frame = heartbeat(5.0f, 2.0f, 0.0f, (1u << 2) | (1u << 10));
  EXPECT_EQ(frame.data[1], 0x04);
  EXPECT_EQ(frame.data[2], 0x04);
  const DecodedFrame d = decode_frame(frame, kNode);
  EXPECT_EQ(d.signals[13].raw, 1);  // fault_overcurrent
  EXPECT_EQ(d.signals[21].raw, 1);  // fault_encoder
  EXPECT_NE(describe(d).find(" faults=overcurrent,encoder"), std::string::npos) << describe(d);
  DriveMonitor monitor(kNode);
  monitor.feed(0.0, frame);
  EXPECT_EQ(monitor.status().heartbeat.fault_bits, (1 << 2) | (1 << 10));
}

TEST(drive_monitor_decode, ShowsTheVersionFrame) {
  hal::CanFrame frame =
      encode_frame(kNode, MessageId::version, {float(protocol::kProtocolVersion), 1, 2, 3, 1});
  const protocol::Message& m = protocol::message(MessageId::version);
  protocol::set_raw(frame.data, m.signals[std::size_t(protocol::find_signal(m, "git_hash"))],
                    0xA2E14617);
  DriveMonitor monitor(kNode);
  monitor.feed(0.0, frame);
  const VersionStatus& v = monitor.status().version;
  EXPECT_EQ(v.count, 1u);
  EXPECT_EQ(v.git_hash, 0xA2E14617u);
  const std::string table = render_table(monitor.status(), kNode, "can0");
  const std::string line = "firmware       1.2.3+ga2e14617.dirty (protocol " +
                           std::to_string(protocol::kProtocolVersion) + ")";
  EXPECT_NE(table.find(line), std::string::npos) << table;
}

TEST(drive_monitor_decode, SortsOutOtherNodesUnknownIdsAndWrongLengths) {
  EXPECT_EQ(decode_frame(encode_frame(2, MessageId::heartbeat, {}), kNode).kind,
            FrameKind::other_node);
  hal::CanFrame unknown;
  unknown.id = protocol::can_id(kNode, MessageId(0x1F));
  EXPECT_EQ(decode_frame(unknown, kNode).kind, FrameKind::unknown_message);
  hal::CanFrame short_heartbeat = heartbeat(1.0f);
  short_heartbeat.length = 5;
  const DecodedFrame d = decode_frame(short_heartbeat, kNode);
  EXPECT_EQ(d.kind, FrameKind::wrong_length);
  EXPECT_EQ(describe(d), "heartbeat (wrong length, expected 8)");
}

TEST(drive_monitor_decode, PrintsValuesAtTheSignalsResolution) {
  const protocol::Signal& speed = protocol::kSpeedFluxSignals[0];  // 0.01 rad/s
  EXPECT_EQ(format_physical(speed, 12345 * 0.01), "123.45");
  EXPECT_EQ(format_physical(speed, -0.01), "-0.01");
  EXPECT_EQ(format_physical(protocol::kSpeedFluxSignals[2], 8099 * 1e-4), "0.8099");  // 1e-4
  EXPECT_EQ(format_physical(protocol::kCurrentSignals[3], 3017 * 0.1), "301.7");      // 0.1 V
  EXPECT_EQ(format_physical(protocol::kHeartbeatSignals[2], 7.0), "7");  // counter
}

TEST(drive_monitor_rows, EmitsARowWhenTheVoltageFrameArrives) {
  DriveMonitor monitor(kNode);
  EXPECT_FALSE(monitor.feed(0.0, heartbeat(3.0f)));
  EXPECT_FALSE(monitor.feed(0.01, speed_flux(123.45f)));
  EXPECT_FALSE(monitor.feed(0.01, current(-1.23f)));
  const auto row = monitor.feed(0.0103, voltage(42.0f));
  ASSERT_TRUE(row);
  EXPECT_DOUBLE_EQ(row->time_s, 0.0103);
  EXPECT_DOUBLE_EQ(row->speed_rad_s, 12345 * 0.01);
  EXPECT_DOUBLE_EQ(row->speed_ref_rad_s, 100.0);
  EXPECT_DOUBLE_EQ(row->flux2_Wb2, 8100 * 1e-4);
  EXPECT_DOUBLE_EQ(row->iA_A, -123 * 0.01);
  EXPECT_DOUBLE_EQ(row->v_bus_V, 3001 * 0.1);
  EXPECT_DOUBLE_EQ(row->u_beta_V, -456 * 0.1);
  EXPECT_EQ(row->sample, 42);
  EXPECT_DOUBLE_EQ(row->rr_scale, 10500 * 1e-4);
  EXPECT_EQ(row->state, "running");
  EXPECT_EQ(row->first_fault, "none");
  EXPECT_EQ(csv_row(*row),
            "0.010300,123.45,100.00,0.8100,0.8000,-1.23,-2.50,0.75,300.1,12.3,-45.6,1.0500,42,"
            "running,"
            "none");
  EXPECT_EQ(monitor.status().frames.rows, 1u);
  EXPECT_EQ(monitor.status().frames.stale_samples, 0u);
}

TEST(drive_monitor_rows, CsvHeaderNamesTheColumns) {
  EXPECT_EQ(csv_header(),
            "time_s,speed_rad_s,speed_ref_rad_s,flux2_Wb2,flux2_ref_Wb2,iA_A,iB_A,load_Nm,"
            "v_bus_V,u_alpha_V,u_beta_V,rr_scale,sample,state,first_fault");
}

TEST(drive_monitor_rows, CombinesTheLatestValuesAndCountsStaleAndIncompleteSamples) {
  DriveMonitor monitor(kNode);
  EXPECT_FALSE(monitor.feed(0.0, voltage(1.0f)));  // started mid-sample: no row
  EXPECT_EQ(monitor.status().frames.incomplete_samples, 1u);
  monitor.feed(0.01, speed_flux(1.0f));
  monitor.feed(0.01, current(1.0f));
  const auto first = monitor.feed(0.01, voltage(2.0f));
  ASSERT_TRUE(first);
  EXPECT_EQ(first->state, "");           // no heartbeat yet
  monitor.feed(0.02, speed_flux(2.0f));  // the current frame of this sample is lost
  const auto second = monitor.feed(0.02, voltage(3.0f));
  ASSERT_TRUE(second);
  EXPECT_DOUBLE_EQ(second->speed_rad_s, 2.0);
  EXPECT_DOUBLE_EQ(second->iA_A, 1.0);
  EXPECT_EQ(monitor.status().frames.stale_samples, 1u);
  EXPECT_EQ(monitor.status().frames.rows, 2u);
}

TEST(drive_monitor_rows, IgnoresOtherNodesAndKeepsTheStatus) {
  DriveMonitor monitor(kNode);
  monitor.feed(0.0, encode_frame(2, MessageId::telemetry_voltage, {1.0f, 1.0f, 1.0f}));
  monitor.feed(0.1, heartbeat(5.0f, 2.0f, 9.0f));
  monitor.feed(0.2, encode_frame(kNode, MessageId::command_ack, {7.0f, 9.0f, 5.0f, 4.0f}));
  monitor.feed(0.3, encode_frame(kNode, MessageId::state_change, {3.0f, 5.0f, 5.0f, 4.0f, 300.0f}));
  monitor.feed(0.4, encode_frame(kNode, MessageId::timing, {12.34f, 56.78f, 2.0f, 100.0f}));
  monitor.feed(0.5, protocol::CommandEncoder(kNode).encode({CommandKind::enable}));
  const DriveStatus& s = monitor.status();
  EXPECT_EQ(s.frames.total, 6u);
  EXPECT_EQ(s.frames.other_nodes, 1u);
  EXPECT_EQ(s.frames.commands, 1u);
  EXPECT_EQ(s.frames.rows, 0u);
  EXPECT_EQ(s.heartbeat.state, 5);
  EXPECT_EQ(s.heartbeat.command_counter, 9);
  EXPECT_EQ(s.ack.result, 5);
  EXPECT_EQ(s.state_change.count, 1u);
  EXPECT_EQ(s.timing.overruns, 2);

  const std::string table = render_table(s, kNode, "can0");
  EXPECT_NE(table.find("state          fault (controller iol)"), std::string::npos) << table;
  EXPECT_NE(table.find("first overcurrent"), std::string::npos) << table;
  EXPECT_NE(table.find("last ack       set_speed counter 9: out_of_range, rejected_total 4"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("last running -> fault (fault) at 300 ms"), std::string::npos) << table;
  EXPECT_NE(table.find("exec mean 12.34 us, max 56.78 us, budget 100.00 us, overruns 2"),
            std::string::npos)
      << table;
}

TEST(drive_monitor_rows, NamesFaultBits) {
  EXPECT_EQ(fault_bit_names(0), "none");
  EXPECT_EQ(fault_bit_names((1 << 2) | (1 << 10)), "overcurrent,encoder");
  EXPECT_EQ(fault_bit_names(int64_t(1) << 40), "40");  // beyond every fault code: its number
}

TEST(drive_monitor_send, BuildsCommandsFromWordsAndValues) {
  std::string error;
  const auto speed = parse_command("set-speed", "-12.5", error);
  ASSERT_TRUE(speed) << error;
  EXPECT_EQ(speed->kind, CommandKind::set_speed);
  EXPECT_FLOAT_EQ(speed->value, -12.5f);
  EXPECT_EQ(describe_command(*speed), "set_speed -12.500 rad/s");
  const auto iol = parse_command("select-controller", "iol", error);
  ASSERT_TRUE(iol) << error;
  EXPECT_EQ(describe_command(*iol), "select_controller iol");
  const auto estop = parse_command("estop", std::nullopt, error);
  ASSERT_TRUE(estop) << error;
  EXPECT_EQ(estop->kind, CommandKind::emergency_stop);
  EXPECT_TRUE(parse_command("set-telemetry-rate", "1000", error)) << error;
  EXPECT_TRUE(parse_command("set-flux", "0.81", error)) << error;
}

TEST(drive_monitor_send, RejectsBadCommandsLocally) {
  const struct {
    const char* name;
    std::optional<std::string> value;
    const char* error;
  } cases[] = {
      {"reboot", std::nullopt, "unknown command 'reboot' (known: enable, disable, estop"},
      {"enable", "1", "enable takes no value, got '1'"},
      {"set-speed", std::nullopt, "set-speed needs a value (RAD_S)"},
      {"set-speed", "fast", "set-speed: 'fast' is not a number"},
      {"set-speed", "12abc", "set-speed: '12abc' is not a number"},
      {"set-speed", "nan", "set-speed: 'nan' is not a number"},
      {"set-speed", "1e300", "set-speed: 1e300 cannot be represented"},
      {"set-speed", "3e6", "set-speed: 3e6 cannot be represented: speed_ref_rad_s spans"},
      {"set-flux", "-0.5", "set-flux: -0.5 cannot be represented"},
      {"set-flux", "0", "set-flux: 0 must be > 0 Wb^2"},
      {"select-controller", "pid", "unknown controller 'pid' (known: dsmc, iol, ifoc)"},
      {"set-telemetry-rate", "5", "must be a whole number of Hz in 10..1000"},
      {"set-telemetry-rate", "100.5", "must be a whole number of Hz in 10..1000"},
  };
  for (const auto& c : cases) {
    std::string error;
    EXPECT_FALSE(parse_command(c.name, c.value, error)) << c.name;
    EXPECT_NE(error.find(c.error), std::string::npos) << c.name << ": " << error;
  }
}

TEST(drive_monitor_send, FindsTheHeartbeatCounterAndTheMatchingAck) {
  EXPECT_EQ(heartbeat_command_counter(heartbeat(1.0f, 0.0f, 11.0f), kNode), 11);
  EXPECT_FALSE(heartbeat_command_counter(heartbeat(1.0f), 2));
  EXPECT_FALSE(heartbeat_command_counter(voltage(1.0f), kNode));
  const hal::CanFrame ack =
      encode_frame(kNode, MessageId::command_ack, {float(MessageId::set_speed), 12.0f, 3.0f, 9.0f});
  const auto matched = match_ack(ack, kNode, uint8_t(MessageId::set_speed), 12);
  ASSERT_TRUE(matched);
  EXPECT_EQ(matched->result, CommandResult::repeated_counter);
  EXPECT_EQ(matched->rejected_total, 9);
  EXPECT_EQ(result_name(matched->result), "repeated_counter");
  EXPECT_FALSE(match_ack(ack, kNode, uint8_t(MessageId::set_speed), 13));
  EXPECT_FALSE(match_ack(ack, kNode, uint8_t(MessageId::enable), 12));
  EXPECT_FALSE(match_ack(ack, 2, uint8_t(MessageId::set_speed), 12));
}

}  // namespace
}  // namespace imd::monitor
