#include "hal_sim/drive/scenario_config.hpp"

#include <algorithm>
#include <cmath>

#include "control/frames.hpp"
#include "firmware/laws/law_registry.hpp"

namespace imd::sim {

SimBoardConfig board_config(const Scenario& s) {
  SimBoardConfig c;
  c.period_s = s.sample_period_s;
  c.substeps = s.substeps;
  c.integrator = s.integrator;
  c.pwm_latency_ticks = s.pwm_latency_ticks;
  c.inner_feedback = s.inner_feedback;
  c.current_source = s.current_fed;
  c.v_bus_V = s.v_bus_V;
  c.inverter = s.inverter;
  c.encoder_cpr = s.encoder_cpr;
  c.adc = s.adc;
  c.seed = s.seed;
  c.drift = {s.Rs_scale_end, s.Rr_scale_end, s.duration_s};
  c.brake = s.brake;
  c.switching_inverter = s.switching_inverter;
  return c;
}

firmware::DriveConfig drive_config(const Scenario& s) {
  firmware::DriveConfig c;
  c.sample_period_s = s.sample_period_s;
  // The loader accepts only the laws' names (hal_sim/scenario.cpp); an unknown one would
  // have stopped there.
  firmware::controller_named(s.controller, c.controller);
  c.iol_period_s = s.iol_period_s;
  // The ideal current source imposes the current at once; the deadbeat loop a tick later.
  c.current_response_ticks = s.current_fed ? 0 : 1;
  c.outer_speed_loop = s.outer_speed_loop;
  c.outer_flux_loop = s.outer_flux_loop;
  c.speed_loop_bandwidth_rad_s = s.speed_loop_bandwidth_rad_s;
  c.torque_limit_Nm = s.torque_limit_Nm;
  c.flux_loop_time_constant_s = s.flux_loop_time_constant_s;
  c.ifoc_current_bandwidth_rad_s = s.ifoc_current_bandwidth_rad_s;
  c.ifoc_speed_bandwidth_rad_s = s.ifoc_speed_bandwidth_rad_s;
  c.magnetized_fraction = s.magnetized_fraction;
  c.magnetizing_current_A = s.magnetizing_current_A;
  c.pwm_latency_ticks = s.pwm_latency_ticks;
  c.compensate_latency = s.compensate_latency;
  c.i_max_A = s.i_max_A;
  c.voltage_limited = s.limit_voltage;
  c.dead_time_s = s.inverter.dead_time_s;  // the board programs it: the firmware knows it
  c.compensate_dead_time = s.dead_time_compensation;
  c.rotor_resistance_tracking = s.rotor_resistance_tracking;
  c.rr_convergence_time_constant_s = s.rr_convergence_time_constant_s;
  c.rr_retune_share = s.rr_retune_share;
  c.max_accel_rad_s2 = s.max_accel_rad_s2;
  c.speed_reaching_pole = s.speed_reaching_pole;
  c.dsmc_paper_speed_channel = s.dsmc_speed_channel == "paper";
  c.dsmc_speed_bandwidth_rad_s = s.dsmc_speed_bandwidth_rad_s;
  c.flux_reaching_pole = s.flux_reaching_pole;
  // Commands: a profile runs at once; over CAN the script enables the drive.
  c.commands_over_can = s.command_source == "can";
  c.auto_enable = !c.commands_over_can;
  c.node_id = static_cast<uint8_t>(s.can_node_id);
  c.telemetry_rate_Hz = static_cast<int>(std::lround(s.telemetry_rate_Hz));
  c.flux2_ref_Wb2 = s.flux2_Wb2;
  c.stator_flux2_ref_Wb2 = s.stator_flux2_Wb2;
  c.max_flux2_Wb2 = 2.0 * std::max(s.flux2_Wb2, s.stator_flux2_Wb2);
  // Protection: defaults from the scenario's board, then its [protection] table.
  firmware::ProtectionConfig& p = c.protection;
  const ProtectionSettings& set = s.protection;
  p.overcurrent_A = set.overcurrent_A.value_or(1.5 * s.i_max_A);
  p.bus_min_V = set.bus_min_V.value_or(0.7 * s.v_bus_V);  // +-30 % of the nominal bus
  p.bus_max_V = set.bus_max_V.value_or(1.3 * s.v_bus_V);
  p.overspeed_rad_s = set.overspeed_rad_s.value_or(p.overspeed_rad_s);
  p.encoder_missing_counts = set.encoder_missing_counts.value_or(p.encoder_missing_counts);
  p.encoder_max_load_share = set.encoder_max_load_share.value_or(p.encoder_max_load_share);
  // The stuck-ADC window is a time (firmware/protection/protection_config.hpp).
  p.adc_stuck_ticks =
      set.adc_stuck_ticks.value_or(firmware::adc_stuck_ticks_for(s.sample_period_s));
  const double A_per_code = 2.0 * s.adc.full_scale_A / double(1 << s.adc.bits);
  p.inverter_voltage_error_share =
      set.inverter_voltage_error_share.value_or(p.inverter_voltage_error_share);
  // The board's ADC noise, if it is more than the drive's default assumes.
  p.adc_noise_codes =
      set.adc_noise_codes.value_or(std::max(p.adc_noise_codes, Real(s.adc.noise_A / A_per_code)));
  p.command_timeout_s = set.command_timeout_s.value_or(p.command_timeout_s);
  const auto stop = [](const std::string& name) {
    using firmware::StopCategory;
    return name == "ss1" ? StopCategory::ss1
                         : (name == "dc_brake" ? StopCategory::dc_brake : StopCategory::sto);
  };
  p.stop = {stop(set.command_timeout_stop), stop(set.emergency_stop_stop), stop(set.encoder_stop)};
  p.dc_brake_current_share = set.dc_brake_current_share.value_or(p.dc_brake_current_share);
  if (s.brake.holding_torque_Nm > 0.0) {  // a brake fitted: its line and its release time
    c.brake_output_line = sim::HoldingBrake::kLine;
    c.brake_release_time_s = s.brake.release_delay_s;
  }
  // Lock-step simulation: the host's wall-clock time per tick is not the MCU's, so the budget
  // is checked only when the scenario sets one.
  p.tick_budget_ns = static_cast<uint32_t>(std::lround(set.tick_budget_us.value_or(0.0) * 1e3));
  c.stop_decel_rad_s2 = set.stop_decel_rad_s2.value_or(c.stop_decel_rad_s2);
  c.adc_calibration_ticks = s.ideal_sensors ? 0 : 256;
  // Ideal sensors give the drive no encoder counts or ADC currents of its own to judge.
  p.check_encoder = p.check_adc_stuck = !s.ideal_sensors;
  c.adc_offset_limit_A = 0.02 * s.adc.full_scale_A;  // 2 % of full scale (0.2 A on 10 A)
  c.section_iv_load_estimator = s.section_iv;
  c.encoder_observer_bandwidth_rad_s = s.encoder_bandwidth_rad_s;
  c.load_estimator_pole = s.load_estimator_pole;
  return c;
}

void prepare_board(SimBoard& board, const Scenario& s) {
  board.set_load_profile(s.load);
  PlantState start;
  start.theta_mech_rad = s.initial_theta_mech_rad;
  const auto rotor =
      control::Rotation<double>::from_angle(s.plant.pole_pairs * s.initial_theta_mech_rad);
  const double flux_Wb = std::sqrt(s.initial_flux2_Wb2);
  start.flux_r_alphabeta_Wb = rotor.apply(Vec2(flux_Wb, 0.0));
  start.i_s_alphabeta_A = rotor.apply(Vec2(flux_Wb / s.plant.Lm_H, 0.0));
  board.plant().set_state(start);
}

ScenarioProfiles profiles(const Scenario& s) {
  return {s.speed, s.flux2_Wb2, s.torque, s.stator_flux2_Wb2};
}

}  // namespace imd::sim
