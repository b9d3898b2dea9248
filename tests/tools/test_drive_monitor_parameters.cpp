// drive_monitor parameters' library: field names, KEY=VALUE checked before anything goes on the
// bus, and the drive's parameter_value answers decoded as the drive encodes them.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "firmware/protocol/commands.hpp"
#include "firmware/protocol/frame_codec.hpp"
#include "tools/drive_monitor/parameter_access.hpp"

namespace imd::monitor {
namespace {

namespace protocol = firmware::protocol;
using firmware::ParameterStatus;

TEST(drive_monitor_parameters, NamesAreTheMotorFilesKeys) {
  EXPECT_EQ(field_named("Rs_Ohm"), uint8_t(firmware::MotorField::Rs_Ohm));
  EXPECT_EQ(field_named("friction_Nms"), uint8_t(firmware::MotorField::friction_Nms));
  EXPECT_FALSE(field_named("rs_ohm").has_value());
  EXPECT_EQ(field_name(uint8_t(firmware::MotorField::Lr_H)), "Lr_H");
  EXPECT_EQ(status_name(ParameterStatus::no_leakage), "no_leakage");
}

TEST(drive_monitor_parameters, AssignmentsAreCheckedLocally) {
  std::string error;
  const auto a = parse_assignment("Rr_Ohm=10.1", error);
  ASSERT_TRUE(a.has_value()) << error;
  EXPECT_EQ(a->field, uint8_t(firmware::MotorField::Rr_Ohm));
  EXPECT_EQ(a->value, 10.1f);
  // Negative values go to the drive, which answers with the rule they break.
  EXPECT_TRUE(parse_assignment("Rs_Ohm=-1", error).has_value());
  for (const char* bad : {"Rr_Ohm", "Rr_Ohm=", "Rr_Ohm=1x", "Rr_Ohm=nan", "Rr_Ohm=1e39",
                          "Xx=1"}) {
    error.clear();
    EXPECT_FALSE(parse_assignment(bad, error).has_value()) << bad;
    EXPECT_FALSE(error.empty()) << bad;
  }
}

TEST(drive_monitor_parameters, DecodesTheDrivesAnswer) {
  const hal::CanFrame frame = protocol::encode_frame(
      3, protocol::MessageId::parameter_value,
      {float(firmware::MotorField::Lm_H), float(protocol::ParameterOp::write),
       float(ParameterStatus::no_leakage), 0.377f, 1.0f, 0.0f});
  const auto reply = decode_parameter_value(frame, 3);
  ASSERT_TRUE(reply.has_value());
  EXPECT_EQ(reply->field, uint8_t(firmware::MotorField::Lm_H));
  EXPECT_EQ(reply->op, protocol::ParameterOp::write);
  EXPECT_EQ(reply->status, ParameterStatus::no_leakage);
  EXPECT_EQ(reply->value, 0.377f);
  EXPECT_TRUE(reply->complete);
  EXPECT_FALSE(reply->saved);
  EXPECT_FALSE(decode_parameter_value(frame, 4).has_value());  // another node's
  const hal::CanFrame none = protocol::encode_frame(
      3, protocol::MessageId::parameter_value,
      {0.0f, 0.0f, float(ParameterStatus::not_set), std::numeric_limits<float>::quiet_NaN()});
  EXPECT_TRUE(std::isnan(decode_parameter_value(none, 3)->value));
}

TEST(drive_monitor_parameters, TheCommandCarriesOpFieldAndValue) {
  const protocol::Command c = parameter_command(protocol::ParameterOp::write, 5, 0.02f);
  protocol::CommandEncoder encoder(1);
  protocol::CommandDecoder decoder(1, {});
  const protocol::Decoded d = decoder.decode(encoder.encode(c));
  ASSERT_EQ(d.result, protocol::CommandResult::accepted);
  EXPECT_EQ(d.command.op, protocol::ParameterOp::write);
  EXPECT_EQ(d.command.field, 5);
  EXPECT_EQ(d.command.value, 0.02f);
}

}  // namespace
}  // namespace imd::monitor

namespace imd::monitor {
namespace {

namespace protocol = firmware::protocol;

hal::CanFrame progress_frame(uint8_t node, float step, float fraction, float failure, float s) {
  return protocol::encode_frame(node, protocol::MessageId::identify_progress,
                                {step, fraction, failure, s});
}

TEST(drive_monitor_identify, DecodesAndShowsTheProgress) {
  const auto p = decode_identify_progress(progress_frame(2, 8.0f, 0.4f, 0.0f, 12.3f), 2);
  ASSERT_TRUE(p.has_value());
  EXPECT_TRUE(p->running());
  EXPECT_FALSE(p->ended());
  EXPECT_EQ(progress_text(*p), "accelerate 40 % (12.3 s)");
  EXPECT_FALSE(decode_identify_progress(progress_frame(2, 8.0f, 0.4f, 0.0f, 1.0f), 3));
  const auto done = decode_identify_progress(progress_frame(2, 4.0f, 1.0f, 0.0f, 16.4f), 2);
  EXPECT_TRUE(done->ended());
  EXPECT_EQ(progress_text(*done), "done (16.4 s)");
  // Done without turning: the reason the mechanics were kept is shown.
  const auto kept = decode_identify_progress(progress_frame(2, 4.0f, 1.0f, 7.0f, 5.0f), 2);
  EXPECT_EQ(progress_text(*kept), "done: no_motion (5.0 s)");
  const auto failed = decode_identify_progress(progress_frame(2, 5.0f, 1.0f, 1.0f, 60.2f), 2);
  EXPECT_EQ(progress_text(*failed), "failed: not_settled (60.2 s)");
  // The heartbeat's state, by which identify knows the result was applied.
  hal::CanFrame heartbeat = protocol::encode_frame(2, protocol::MessageId::heartbeat, {1.0f});
  EXPECT_EQ(heartbeat_state(heartbeat, 2), firmware::DriveState::idle);
  EXPECT_FALSE(heartbeat_state(heartbeat, 3).has_value());
  // Before a run: "none" is neither running nor ended.
  const auto idle = decode_identify_progress(progress_frame(2, 6.0f, 0.0f, 0.0f, 0.0f), 2);
  EXPECT_FALSE(idle->running() || idle->ended());
}

}  // namespace
}  // namespace imd::monitor
