// The DSMC's speed channel through the torque (control/dsmc.hpp, docs/control.md): on the
// realistic board it tracks as well as the paper's channel without the q current ringing at
// half the sample rate. The bounds are the acceptance of docs/results.md ("A sliding-mode law
// without chattering"), measured against the IFOC on the same run.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "hal_sim/drive/scenario_run.hpp"
#include "hal_sim/scenario.hpp"
#include "test_motors.hpp"

namespace imd::sim {
namespace {

Summary run(const std::string& file, std::vector<std::string> overrides) {
  return run_scenario(load_scenario(test::source_path(file), overrides));
}

const char* kSeed000 = "hal_sim/scenarios/seed000_realistic.toml";

void print(const char* what, const Summary& r) {
  std::printf(
      "%-22s speed rms %.4f rad/s, flux2 rms %.3e Wb^2, control-rate ripple %.4f A, voltage "
      "ripple %.3f V, on the limit %.4f\n",
      what, r.speed_rms_err_rad_s, r.flux2_rms_err_Wb2, r.current_ripple_control_rms_A,
      r.voltage_ripple_rms_V, r.saturated_fraction);
}

TEST(DsmcTorqueChannel, TracksLikeThePapersChannelWithoutItsRipple) {
  const Summary torque = run(kSeed000, {});
  const Summary paper = run(kSeed000, {"drive.dsmc_speed_channel=paper"});
  const Summary ifoc = run(kSeed000, {"drive.controller=ifoc"});
  print("dsmc, torque channel", torque);
  print("dsmc, paper's channel", paper);
  print("ifoc", ifoc);
  for (const Summary* r : {&torque, &paper, &ifoc}) EXPECT_TRUE(r->faults.empty());
  // The paper's channel: 0.079 rad/s RMS on this run. Within 1.2x of it.
  EXPECT_LE(torque.speed_rms_err_rad_s, 1.2 * 0.079);
  // The ripple within 2x of the IFOC's (the paper's channel: 30x), and the voltage limit in
  // under 5 % of the ticks (the paper's channel: 30 %).
  EXPECT_LE(torque.current_ripple_control_rms_A, 2.0 * ifoc.current_ripple_control_rms_A);
  EXPECT_LT(torque.saturated_fraction, 0.05);
  EXPECT_GT(paper.current_ripple_control_rms_A, 10.0 * torque.current_ripple_control_rms_A);
  // The flux: within 1 % of its reference (measured 0.54 % over ADC seeds 1-4; the paper's
  // channel, which sets the flux of the next step directly, 0.07 %).
  EXPECT_LE(torque.flux2_rms_err_Wb2, 0.01 * 0.2);
}

TEST(DsmcTorqueChannel, MeetsItsTargetsWithTheSwitchingInverter) {
  // The inverter's switches simulated (inverter.model = "switching"): the current ripple
  // within each PWM period is then real. The acceptance: speed within 1.2x of the
  // paper channel's 0.079 rad/s, the ripple within 2x the IFOC's on the same run, the voltage
  // limit in under 5 % of the ticks.
  const Summary torque = run(kSeed000, {"inverter.model=switching"});
  const Summary paper =
      run(kSeed000, {"inverter.model=switching", "drive.dsmc_speed_channel=paper"});
  const Summary ifoc = run(kSeed000, {"inverter.model=switching", "drive.controller=ifoc"});
  std::printf(
      "switching inverter, PWM ripple: torque channel %.4f A, paper's %.4f A, ifoc %.4f A\n",
      torque.current_ripple_rms_A, paper.current_ripple_rms_A, ifoc.current_ripple_rms_A);
  print("sw: dsmc, torque", torque);
  print("sw: dsmc, paper's", paper);
  print("sw: ifoc", ifoc);
  for (const Summary* r : {&torque, &paper, &ifoc}) EXPECT_TRUE(r->faults.empty());
  EXPECT_LE(torque.speed_rms_err_rad_s, 1.2 * 0.079);
  EXPECT_LE(torque.current_ripple_rms_A, 2.0 * ifoc.current_ripple_rms_A);
  EXPECT_LE(torque.current_ripple_control_rms_A, 2.0 * ifoc.current_ripple_control_rms_A);
  EXPECT_LT(torque.saturated_fraction, 0.05);
}

TEST(DsmcTorqueChannel, HoldsALoadAtStandstillWithTheIfocsVoltage) {
  // Zero speed, 1 N m: the alternating voltage (the control-rate ripple of what the inverter
  // applies) within 2x of the IFOC's. The paper's channel applies about 100x as much.
  const std::vector<std::string> hold = {"reference.speed.amplitude_rad_s=0", "load.low_Nm=1.0",
                                         "simulation.duration_s=3", "metrics.settle_s=1"};
  auto with = [&](std::vector<std::string> more) {
    more.insert(more.end(), hold.begin(), hold.end());
    return run(kSeed000, more);
  };
  const Summary torque = with({});
  const Summary paper = with({"drive.dsmc_speed_channel=paper"});
  const Summary ifoc = with({"drive.controller=ifoc"});
  print("hold: torque channel", torque);
  print("hold: paper's channel", paper);
  print("hold: ifoc", ifoc);
  for (const Summary* r : {&torque, &paper, &ifoc}) EXPECT_TRUE(r->faults.empty());
  EXPECT_LE(torque.voltage_ripple_rms_V, 2.0 * ifoc.voltage_ripple_rms_V);
  EXPECT_GT(paper.voltage_ripple_rms_V, 10.0 * torque.voltage_ripple_rms_V);
}

TEST(DsmcTorqueChannel, WeakensTheFieldAboveBaseSpeed) {
  // 400 rad/s, 1.25 x the paper-000 motor's base speed on the 311 V bus, ramped at
  // 100 rad/s^2, 0.3 N m load (compare_controllers' field_weakening case): the flux reference
  // falls to what the voltage allows (control/field_weakening.hpp) and the speed is reached.
  // Without it the DSMC stayed 114 rad/s short at full voltage. The IFOC's figure is 0.01.
  const std::vector<std::string> fast = {
      "reference.speed.amplitude_rad_s=0", "reference.speed.offset_rad_s=400.0",
      "drive.max_accel_rad_s2=100.0",      "load.low_Nm=0.3",
      "load.high_Nm=0.3",                  "protection.overspeed_rad_s=600.0",
      "simulation.duration_s=6.0",         "metrics.settle_s=5.0"};
  const Summary r = run(kSeed000, fast);
  print("field weakening", r);
  EXPECT_TRUE(r.faults.empty());
  // 1 % of the reference, where the IFOC tracks to 0.0025 %: the DSMC's own figure is 0.006.
  EXPECT_LT(r.speed_rms_err_rad_s, 0.01 * 400.0);
  EXPECT_LE(r.i_peak_total_A, 6.0);
}

TEST(DsmcTorqueChannel, DoesNotRingOnTheOtherMotors) {
  // The 0.75 kW four-pole and the 7.5 kW six-pole motors: the paper's channel rings (0.09 A and
  // 2.4 A of control-rate ripple), the torque channel not (0.0007 A, 0.022 A): a tenth bounds it.
  for (const char* file : {"tests/data/scenarios/small_4pole_750W_realistic.toml",
                           "tests/data/scenarios/six_pole_7kW_realistic.toml",
                           "tests/data/scenarios/two_pole_550W_realistic.toml",
                           "tests/data/scenarios/eight_pole_15kW_realistic.toml"}) {
    const Summary torque = run(file, {});
    const Summary paper = run(file, {"drive.dsmc_speed_channel=paper"});
    print(file, torque);
    EXPECT_TRUE(torque.faults.empty()) << file;
    EXPECT_LT(torque.current_ripple_control_rms_A, 0.1 * paper.current_ripple_control_rms_A)
        << file;
    EXPECT_LT(torque.saturated_fraction, 0.05) << file;
  }
}

}  // namespace
}  // namespace imd::sim
