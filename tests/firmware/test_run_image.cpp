// The drive as the STM32G431's run image builds it: the DSMC alone and no commissioning
// (firmware/image_features.hpp; this test links a library built with the run image's
// definitions). The laws and the commissioning it leaves out are refused over CAN with
// `not_in_image`, the refusal changes nothing, and the law it carries runs.
#include <gtest/gtest.h>

#include <tuple>
#include <type_traits>

#include "firmware/can_rig.hpp"

namespace imd::firmware {
namespace {

using protocol::CommandKind;
using protocol::CommandResult;

static_assert(!kCommissioningInImage && law_in_image(ControllerKind::dsmc) &&
                  !law_in_image(ControllerKind::iol) && !law_in_image(ControllerKind::ifoc),
              "this test runs on the run image's definitions");
// The other laws are not compiled in, not merely unused.
static_assert(std::is_same_v<Laws<double>, std::tuple<DsmcLaw<double>>>);
static_assert(std::is_same_v<Laws<float>, std::tuple<DsmcLaw<float>>>);

TEST(RunImage, RefusesTheLawsAndTheCommissioningItDoesNotCarryAndChangesNothing) {
  CanRig rig;
  rig.run(300);  // offset calibration
  ASSERT_EQ(rig.drive.state(), DriveState::idle);
  const uint32_t rejected_before = rig.drive.commands().rejected(CommandResult::not_in_image);
  rig.send({CommandKind::select_controller, 1.0f});  // iol
  rig.run(1);
  rig.send({CommandKind::select_controller, 2.0f});  // ifoc
  rig.run(1);
  rig.send({CommandKind::identify, 0.0f});
  rig.run(1);
  rig.send({CommandKind::identify, 1.0f});  // with the rotating test
  rig.run(50);
  const std::vector<CommandResult> acks = rig.acks();
  ASSERT_EQ(acks.size(), 4u);
  for (const CommandResult r : acks) EXPECT_EQ(r, CommandResult::not_in_image);
  // Counted as rejections, as every refusal is (the command_ack's rejected total).
  EXPECT_EQ(rig.drive.commands().rejected(CommandResult::not_in_image) - rejected_before, 4u);
  EXPECT_EQ(rig.drive.state(), DriveState::idle);
  EXPECT_EQ(rig.drive.fault(), FaultCode::none);
  EXPECT_EQ(rig.drive.status().controller, static_cast<uint8_t>(ControllerKind::dsmc));
  EXPECT_FALSE(rig.board.pwm().enabled());
  // The law it carries is still selectable.
  rig.send({CommandKind::select_controller, 0.0f});
  rig.run(1);
  EXPECT_EQ(rig.acks().back(), CommandResult::accepted);
}

TEST(RunImage, RunsItsLaw) {
  CanRig rig;
  rig.run(300);
  rig.enable_at(30.0f);
  ASSERT_EQ(rig.drive.state(), DriveState::running);
  rig.hold(30.0f, 10000);  // 1 s
  // As in DriveCommands.EnableRuns...: the realistic board holds speed to 0.08 rad/s RMS
  // (docs/results.md); 0.5 rad/s is over six times that, far from a drive that did not run.
  EXPECT_NEAR(rig.board.plant().state().omega_mech_rad_s, 30.0, 0.5);
  EXPECT_EQ(rig.drive.fault(), FaultCode::none);
}

}  // namespace
}  // namespace imd::firmware
