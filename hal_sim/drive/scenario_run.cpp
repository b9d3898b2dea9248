#include "hal_sim/drive/scenario_run.hpp"

#include <bit>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "control/current_fed_model.hpp"
#include "control/frames.hpp"
#include "firmware/drive.hpp"
#include "hal_sim/run_metrics.hpp"
#include "hal_sim/drive/scenario_config.hpp"
#include "hal_sim/drive/simulated_drive.hpp"
#include "hal_sim/sim_board.hpp"
#include "hal_sim/sim_can_host.hpp"
#include "hal_sim/drive/scripted_commands.hpp"

namespace imd::sim {
namespace {

template <typename T>
Summary run(const Scenario& s, const RunCallbacks& callbacks) {
  SimBoard board(s.motor, sim::board_config(s));
  sim::prepare_board(board, s);
  const sim::ScenarioReferences<T> references(s);
  SimulatedDrive<T> simulated(board, s.motor, sim::drive_config(s),
                              {s.ideal_sensors, s.inner_feedback, s.current_fed}, &references,
                              board.timer(), &board.can());
  firmware::Drive<T>& drive = simulated.drive();
  const std::vector<ScriptedFrame> commands = scripted_frames(s);
  std::size_t next_command = 0, next_fault = 0;
  std::vector<std::size_t> unanswered;        // injected faults not yet detected (indices)
  std::vector<std::size_t> awaiting_pwm_off;  // detected faults with the PWM still on
  board.timer().start(drive);

  Summary summary;
  const auto wall_start = std::chrono::steady_clock::now();
  auto last_progress = wall_start;
  const auto ticks = static_cast<uint64_t>(std::llround(s.duration_s / s.sample_period_s));
  const control::MotorParameters& m = s.motor;
  sim::RunMetrics metrics(s.settle_s);
  double torque_sq = 0;
  uint64_t torque_count = 0;
  double hold_sq = 0;
  uint64_t hold_count = 0;
  const bool iol = s.controller == "iol";
  const double flux_decay = control::discretize_current_fed(m, s.iol_period_s).flux_decay;
  Vec2 boundary_flux_s = Vec2::Zero();       // true stator flux (rotor frame) at the last boundary
  double pending_torque_cmd = std::nan("");  // the law's v1, due at the next boundary
  struct {
    double torque_ref_Nm = 0.0, y2 = 0.0, y2_ref = 0.0;
  } held;  // iol values of the last boundary, held until the next
  std::vector<hal::CanFrame> sent_frames;  // reused: no allocation per tick
  uint16_t last_fault_bits = 0;
  bool diverged = false;
  for (uint64_t k = 0; k < ticks; ++k) {
    const double t_s = double(k) * s.sample_period_s;
    // Host and board events due before this tick: scripted command frames and faults.
    for (; next_command < commands.size() && commands[next_command].tick <= k; ++next_command) {
      board.can_side().inject(
          commands[next_command].frame);  // a full queue loses it, as a bus would
    }
    for (; next_fault < s.faults.size() && s.faults[next_fault].at_s <= t_s + 1e-12; ++next_fault) {
      // load_scenario refuses such faults; a scenario built in code may still hold one.
      if (!board.inject(s.faults[next_fault])) {
        throw std::invalid_argument(s.source + ": " + fault_parameter_error(s.faults[next_fault]));
      }
      unanswered.push_back(summary.faults.size());
      summary.faults.push_back(
          {"none", fault_kind_name(s.faults[next_fault].kind), t_s, std::nan(""), std::nan("")});
    }
    const PlantState truth = board.plant().state();
    if (!truth.flux_r_alphabeta_Wb.allFinite() || !truth.i_s_alphabeta_A.allFinite() ||
        !std::isfinite(truth.omega_mech_rad_s) || !std::isfinite(truth.theta_mech_rad)) {
      summary.faults.push_back({"plant_diverged", "", std::nan(""), t_s, std::nan("")});
      summary.ticks = k;
      diverged = true;
      break;
    }
    const double load_Nm = board.load_Nm();
    board.run_tick();
    const firmware::TickRecord<T>& rec = drive.record();
    take_all_sent(board.can_side(), sent_frames);
    if (callbacks.can_frame) {
      for (const hal::CanFrame& frame : sent_frames) callbacks.can_frame(t_s, frame);
    }

    SimRow row;
    row.t_s = t_s;
    row.omega_mech_rad_s = truth.omega_mech_rad_s;
    row.omega_ref_rad_s = s.command_source == "can" ? rec.omega_ref_rad_s : s.speed.at(t_s);
    row.omega_est_rad_s = rec.omega_est_rad_s;
    const auto rotor = control::Rotation<double>::from_angle(m.pole_pairs * truth.theta_mech_rad);
    const Vec2 flux_AB = rotor.apply_inverse(truth.flux_r_alphabeta_Wb);
    row.flux_A_Wb = flux_AB.x();
    row.flux_B_Wb = flux_AB.y();
    row.flux2_Wb2 = flux_AB.squaredNorm();
    row.flux2_ref_Wb2 = s.flux2_Wb2;
    row.flux2_est_Wb2 = rec.flux2_est_Wb2;
    row.flux_A_est_Wb = rec.flux_est_AB_Wb.x();
    row.flux_B_est_Wb = rec.flux_est_AB_Wb.y();
    row.load_Nm = load_Nm;
    row.load_est_Nm = rec.load_est_Nm;
    row.i_alpha_A = truth.i_s_alphabeta_A.x();
    row.i_beta_A = truth.i_s_alphabeta_A.y();
    row.v_alpha_V = board.applied_voltage_V().x();
    row.v_beta_V = board.applied_voltage_V().y();
    row.discriminant = rec.law.discriminant;
    row.c_k = rec.law.c_k;
    row.theta_mech_rad = truth.theta_mech_rad;
    row.theta_est_rad = rec.theta_est_rad;
    row.torque_Nm = board.start_torque_Nm();
    {
      const Vec2 flux_s_AB = rotor.apply_inverse(board.start_flux_s_alphabeta_Wb());
      row.stator_flux2_Wb2 = flux_s_AB.squaredNorm();
      row.stator_flux2_ref_Wb2 = s.stator_flux2_Wb2;
      row.iol_boundary = rec.law.iol_boundary;
      if (rec.law.iol_boundary) {
        // y2 of (20) from the true stator fluxes of this and the last boundary.
        held.y2 = flux_s_AB.dot(boundary_flux_s) - flux_decay * boundary_flux_s.squaredNorm();
        boundary_flux_s = flux_s_AB;
        if (std::isfinite(pending_torque_cmd) && t_s > s.settle_s) {
          torque_sq += (row.torque_Nm - pending_torque_cmd) * (row.torque_Nm - pending_torque_cmd);
          ++torque_count;
        }
        pending_torque_cmd = rec.law.torque_cmd_Nm;
        held.torque_ref_Nm = rec.law.torque_ref_Nm;
        held.y2_ref = rec.law.y2_ref;
      }
      // How far the stator current departs from the rotor-frame zero-order hold paper 001
      // assumes: the current at the start of the period (after any step) against the current
      // the law takes as held over it.
      const Vec2 i_AB = rotor.apply_inverse(board.start_current_alphabeta_A());
      row.i_hold_err_A = iol && rec.state == firmware::DriveState::running
                             ? (i_AB - rec.law.i_held_AB_A.template cast<double>()).norm()
                             : 0.0;
      if (iol && t_s > s.settle_s) {
        hold_sq += row.i_hold_err_A * row.i_hold_err_A;
        ++hold_count;
      }
      row.y2 = held.y2;
      row.y2_ref = held.y2_ref;
      row.torque_ref_Nm = held.torque_ref_Nm;
    }
    row.state = static_cast<int>(rec.state);
    row.omega_ref_cmd_rad_s = rec.omega_ref_rad_s;
    row.flux2_ctrl_est_Wb2 = rec.controlled_flux2_Wb2;
    row.flux2_ctrl_ref_Wb2 = rec.controlled_flux2_ref_Wb2;
    row.iA_est_A = rec.i_s_est_AB_A.x();
    row.iB_est_A = rec.i_s_est_AB_A.y();
    row.v_bus_meas_V = rec.v_bus_V;
    row.u_alpha_cmd_V = rec.u_alphabeta_V.x();
    row.u_beta_cmd_V = rec.u_alphabeta_V.y();
    row.saturated = rec.law.speed_saturated || rec.law.flux_saturated || rec.voltage_clipped;

    const double current_A = truth.i_s_alphabeta_A.norm();
    if (summary.running_from_s < 0 && rec.state == firmware::DriveState::running)
      summary.running_from_s = t_s;
    // Faults the drive latched this tick, the first one first; each answers the oldest
    // injected fault still unanswered.
    for (uint16_t fresh = rec.fault_bits & ~last_fault_bits; fresh != 0;) {
      int code = std::countr_zero(fresh);
      if ((fresh & (1u << unsigned(rec.fault))) != 0) code = int(rec.fault);
      fresh = uint16_t(fresh & ~(1u << unsigned(code)));
      std::size_t event = summary.faults.size();
      if (!unanswered.empty()) {
        event = unanswered.front();
        unanswered.erase(unanswered.begin());
      } else {
        summary.faults.push_back({});
      }
      summary.faults[event].code = firmware::fault_name(firmware::FaultCode(code));
      summary.faults[event].detected_at_s = t_s;
      awaiting_pwm_off.push_back(event);
    }
    last_fault_bits = rec.fault_bits;
    if (!board.pwm().enabled()) {
      for (const std::size_t event : awaiting_pwm_off) summary.faults[event].pwm_off_at_s = t_s;
      awaiting_pwm_off.clear();
    }
    // Over CAN the drive is stopped and started at the host's will: only running ticks count.
    metrics.add({t_s, s.command_source != "can" || rec.state == firmware::DriveState::running,
                 row.omega_mech_rad_s - row.omega_ref_rad_s,
                 iol ? row.stator_flux2_Wb2 - row.stator_flux2_ref_Wb2
                     : row.flux2_Wb2 - row.flux2_ref_Wb2,
                 row.load_est_Nm - row.load_Nm, current_A, row.saturated});
    if (callbacks.row) callbacks.row(row);
    if (callbacks.progress && (k & 1023) == 0) {
      const auto now = std::chrono::steady_clock::now();
      if (now - last_progress > std::chrono::seconds(1)) {
        last_progress = now;
        callbacks.progress(t_s, std::chrono::duration<double>(now - wall_start).count());
      }
    }
  }
  if (!diverged) summary.ticks = ticks;
  summary.simulated_s = double(summary.ticks) * s.sample_period_s;
  summary.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  // Nothing after settle_s (a run that ended early): the metrics are not defined (null in JSON).
  summary.speed_rms_err_rad_s = metrics.speed_rms_err_rad_s();
  summary.speed_max_err_rad_s = metrics.speed_max_err_rad_s();
  summary.flux2_rms_err_Wb2 = metrics.flux2_rms_err_Wb2();
  summary.flux2_max_err_Wb2 = metrics.flux2_max_err_Wb2();
  summary.load_est_rms_err_Nm = metrics.load_est_rms_err_Nm();
  summary.i_peak_A = metrics.i_peak_A();
  summary.i_peak_total_A = metrics.i_peak_total_A();
  summary.saturated_fraction = metrics.saturated_fraction();
  if (iol && !s.outer_speed_loop) {  // a torque-controlled run has no speed reference
    summary.speed_rms_err_rad_s = summary.speed_max_err_rad_s = std::nan("");
  }
  summary.i_hold_rms_err_A =
      hold_count > 0 ? std::sqrt(hold_sq / double(hold_count)) : std::nan("");
  summary.torque_rms_err_Nm =
      torque_count > 0 ? std::sqrt(torque_sq / double(torque_count)) : std::nan("");
  summary.tick_exec_ns_mean = drive.execution().mean_ns();
  summary.tick_exec_ns_max = drive.execution().max_ns;
  return summary;
}

}  // namespace

Summary run_scenario(const Scenario& scenario, const RunCallbacks& callbacks) {
  return scenario.precision == "float" ? run<float>(scenario, callbacks)
                                       : run<double>(scenario, callbacks);
}

}  // namespace imd::sim
