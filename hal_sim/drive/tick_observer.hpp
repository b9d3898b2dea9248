#pragma once
/// What a simulated run shows tick by tick, and the tracking metrics over it: the one place
/// that reads the drive's TickRecord for the harness. drive_sim (through the scenario runner),
/// the sim-tier tests and the processor-in-the-loop image use it alike, so their metrics agree.
/// No heap: the PIL image runs it on the MCU, between ticks.
#include <cmath>
#include <cstdint>

#include "control/current_fed_model.hpp"
#include "control/frames.hpp"
#include "firmware/drive_config.hpp"
#include "firmware/tick_record.hpp"
#include "hal_sim/drive/scenario_profiles.hpp"
#include "hal_sim/run_metrics.hpp"
#include "hal_sim/sim_board.hpp"

namespace imd::sim {

/// One row per tick: the plant's true state at t_k, and what the drive estimated and commanded.
struct SimRow {
  double t_s = 0.0;
  double omega_mech_rad_s = 0.0, omega_ref_rad_s = 0.0, omega_est_rad_s = 0.0;
  double flux2_Wb2 = 0.0, flux2_ref_Wb2 = 0.0, flux2_est_Wb2 = 0.0;
  double load_Nm = 0.0, load_est_Nm = 0.0;
  double i_alpha_A = 0.0, i_beta_A = 0.0;
  double v_alpha_V = 0.0, v_beta_V = 0.0;  ///< voltage the plant saw over [t_k, t_{k+1}]
  double discriminant = 0.0, c_k = 0.0;
  double flux_A_Wb = 0.0, flux_B_Wb = 0.0, flux_A_est_Wb = 0.0, flux_B_est_Wb = 0.0;
  double theta_mech_rad = 0.0, theta_est_rad = 0.0;
  double torque_Nm = 0.0;  ///< at the start of the period, with its current
  // The current-fed controller (iol): at T0 boundaries (iol_boundary), else held.
  double torque_ref_Nm = 0.0, y2 = 0.0, y2_ref = 0.0, stator_flux2_Wb2 = 0.0;
  double stator_flux2_ref_Wb2 = 0.0;
  double i_hold_err_A = 0.0;  ///< |i_AB - i_cmd|: departure from the zero-order hold (iol)
  // What the drive's telemetry carries (the CAN round trip compares against these).
  double omega_ref_cmd_rad_s = 0.0;  ///< the speed reference the law aimed at (after the ramp)
  double flux2_ctrl_est_Wb2 = 0.0, flux2_ctrl_ref_Wb2 = 0.0;  ///< the controlled flux
  double iA_est_A = 0.0, iB_est_A = 0.0;  ///< estimated stator current, rotor frame
  double v_bus_meas_V = 0.0;
  double u_alpha_cmd_V = 0.0, u_beta_cmd_V = 0.0;  ///< stator voltage command
  double rr_est_Ohm = 0.0;    ///< the drive's rotor resistance (tracked, or its model's)
  double Rr_plant_Ohm = 0.0;  ///< the plant's over the period
  bool iol_boundary = false;
  int state = 0;
  bool saturated = false;
  int limited = 0;  ///< the drive's `limited` (firmware::Limitation: 0 none, 1 voltage, ...)
  int stop = 0;     ///< the latched fault's stop (firmware::StopCategory: 0 none, 1 sto, ...)
  bool brake_line_engaged = true;  ///< the drive's brake line: not driven
  bool brake_engaged = true;       ///< the board's brake torque acts (after its delays)
};

/// What the rows and the metrics take from the scenario.
struct ObservedRun {
  ScenarioProfiles references;
  double settle_s = 0.5;
  int pole_pairs = 1;
  bool current_fed_law = false;    ///< iol: stator flux, torque and hold metrics
  bool speed_reference = true;     ///< false: a torque-controlled run has no speed metric
  bool commands_over_can = false;  ///< the speed reference is the drive's, running ticks only
  double flux_decay = 0.0;         ///< e^{-eta T0} of the current-fed model (iol)
  /// Ticks from the tick that records a speed command to the step it is for: the law aims at
  /// the step after the input's, which acts pwm_latency_ticks later (1 or 2).
  int command_lead_ticks = 2;
};

/// The observed run of a drive with this configuration.
inline ObservedRun observed_run(const ScenarioProfiles& references, double settle_s,
                                const control::MotorParameters& motor,
                                const firmware::DriveConfig& drive) {
  const bool iol = drive.controller == firmware::ControllerKind::iol;
  return {references,
          settle_s,
          motor.pole_pairs,
          iol,
          !(iol && !drive.outer_speed_loop),
          drive.commands_over_can,
          control::discretize_current_fed(motor, drive.iol_period_s).flux_decay,
          drive.pwm_latency_ticks + 1};
}

template <typename T>
class TickObserver {
 public:
  explicit TickObserver(const ObservedRun& run) noexcept : run_(run), metrics_(run.settle_s) {}

  /// Tick k's row: `truth` and `load_Nm` at t_k (before the tick), `board` after its period,
  /// `rec` the drive's record of the tick. Adds it to the metrics.
  const SimRow& observe(double t_s, const PlantState& truth, double load_Nm, const SimBoard& board,
                        const firmware::TickRecord<T>& rec) noexcept;

  const RunMetrics& metrics() const noexcept { return metrics_; }
  /// NaN when the run has no speed reference (torque control) or nothing was measured.
  double speed_rms_err_rad_s() const noexcept {
    return run_.speed_reference ? metrics_.speed_rms_err_rad_s() : std::nan("");
  }
  double speed_max_err_rad_s() const noexcept {
    return run_.speed_reference ? metrics_.speed_max_err_rad_s() : std::nan("");
  }
  /// The speed against the drive's own command for the same step (after its acceleration
  /// ramp), over the running ticks after settle_s: how well the drive follows what it was told,
  /// without the ramp that a stepped reference with max_accel_rad_s2 adds to the error above.
  double speed_rms_err_cmd_rad_s() const noexcept {
    return run_.speed_reference ? rms(command_sq_, command_count_) : std::nan("");
  }
  /// iol: torque against the law's command one T0 earlier, and |i_AB - i_held| (NaN otherwise).
  double torque_rms_err_Nm() const noexcept { return rms(torque_sq_, torque_count_); }
  double i_hold_rms_err_A() const noexcept { return rms(hold_sq_, hold_count_); }
  double running_from_s() const noexcept { return running_from_s_; }  ///< -1: never
  /// The drive's rotor resistance at the last tick with an estimate, the plant's then, and the
  /// largest |estimate/plant - 1| after settle_s (NaN: no estimate).
  double rr_estimate_final_Ohm() const noexcept { return rr_final_Ohm_; }
  double plant_Rr_final_Ohm() const noexcept { return plant_Rr_final_Ohm_; }
  double rr_rel_err_max() const noexcept { return rr_rel_err_max_; }
  /// The ripple at the control rate after settle_s: the RMS over the phases of
  /// (x_{k+1} - 2 x_k + x_{k-1}) / 4, which passes a period-2 oscillation (f_s / 2) whole,
  /// f_s / 4 at half, and nothing of a ramp; for the plant's phase currents at the samples and
  /// the voltage it saw over each period. NaN: not measured.
  double current_ripple_control_rms_A() const noexcept { return rms(ripple_i_sq_, ripple_count_); }
  double voltage_ripple_rms_V() const noexcept { return rms(ripple_v_sq_, ripple_count_); }
  /// With the switching inverter: the RMS per phase of the current minus its average over each
  /// period (the PWM's ripple, f_s and above), after settle_s. NaN with the average model.
  double current_ripple_rms_A() const noexcept { return rms(pwm_ripple_sq_, pwm_ripple_count_); }

 private:
  static double rms(double sum_sq, uint64_t n) noexcept {
    return n > 0 ? std::sqrt(sum_sq / double(n)) : std::nan("");
  }
  void observe_current_fed(double t_s, const Vec2& flux_s_AB, const Vec2& i_AB,
                           const firmware::TickRecord<T>& rec) noexcept;

  ObservedRun run_;
  RunMetrics metrics_;
  SimRow row_;
  double running_from_s_ = -1.0;
  double rr_final_Ohm_ = std::nan(""), plant_Rr_final_Ohm_ = std::nan("");
  double rr_rel_err_max_ = std::nan("");
  Vec2 i_last_[2] = {Vec2::Zero(), Vec2::Zero()}, v_last_[2] = {Vec2::Zero(), Vec2::Zero()};
  uint64_t rows_seen_ = 0, ripple_count_ = 0;
  double ripple_i_sq_ = 0.0, ripple_v_sq_ = 0.0;
  double pwm_ripple_sq_ = 0.0;
  uint64_t pwm_ripple_count_ = 0;
  double torque_sq_ = 0, hold_sq_ = 0;
  double commands_[3] = {0.0, 0.0, 0.0};  ///< the last ticks' speed commands, by tick mod 3
  uint64_t running_ticks_ = 0;            ///< consecutive running ticks up to this one
  double command_sq_ = 0;
  uint64_t command_count_ = 0;
  uint64_t torque_count_ = 0, hold_count_ = 0;
  Vec2 boundary_flux_s_ = Vec2::Zero();       ///< true stator flux (rotor frame), last boundary
  double pending_torque_cmd_ = std::nan("");  ///< the law's v1, due at the next boundary
  double held_torque_ref_Nm_ = 0.0, held_y2_ = 0.0, held_y2_ref_ = 0.0;  ///< of the boundary
};

template <typename T>
const SimRow& TickObserver<T>::observe(double t_s, const PlantState& truth, double load_Nm,
                                       const SimBoard& board,
                                       const firmware::TickRecord<T>& rec) noexcept {
  SimRow& row = row_;
  row = SimRow{};
  row.t_s = t_s;
  row.omega_mech_rad_s = truth.omega_mech_rad_s;
  row.omega_ref_rad_s =
      run_.commands_over_can ? double(rec.omega_ref_rad_s) : run_.references.speed.at(t_s);
  row.omega_est_rad_s = rec.omega_est_rad_s;
  const auto rotor = control::Rotation<double>::from_angle(run_.pole_pairs * truth.theta_mech_rad);
  const Vec2 flux_AB = rotor.apply_inverse(truth.flux_r_alphabeta_Wb);
  row.flux_A_Wb = flux_AB.x();
  row.flux_B_Wb = flux_AB.y();
  row.flux2_Wb2 = flux_AB.squaredNorm();
  row.flux2_ref_Wb2 = run_.references.flux2_Wb2;
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
  const Vec2 flux_s_AB = rotor.apply_inverse(board.start_flux_s_alphabeta_Wb());
  row.stator_flux2_Wb2 = flux_s_AB.squaredNorm();
  row.stator_flux2_ref_Wb2 = run_.references.stator_flux2_Wb2;
  observe_current_fed(t_s, flux_s_AB, rotor.apply_inverse(board.start_current_alphabeta_A()), rec);
  row.state = static_cast<int>(rec.state);
  row.omega_ref_cmd_rad_s = rec.omega_ref_rad_s;
  row.flux2_ctrl_est_Wb2 = rec.controlled_flux2_Wb2;
  row.flux2_ctrl_ref_Wb2 = rec.controlled_flux2_ref_Wb2;
  row.iA_est_A = rec.i_s_est_AB_A.x();
  row.iB_est_A = rec.i_s_est_AB_A.y();
  row.v_bus_meas_V = rec.v_bus_V;
  row.u_alpha_cmd_V = rec.u_alphabeta_V.x();
  row.u_beta_cmd_V = rec.u_alphabeta_V.y();
  row.rr_est_Ohm = rec.rr_est_Ohm;
  row.Rr_plant_Ohm = board.plant().motor().Rr_Ohm;
  if (rec.rr_est_Ohm > T(0)) {
    rr_final_Ohm_ = row.rr_est_Ohm;
    plant_Rr_final_Ohm_ = row.Rr_plant_Ohm;
    if (t_s > run_.settle_s) {
      const double err = std::abs(row.rr_est_Ohm / row.Rr_plant_Ohm - 1.0);
      rr_rel_err_max_ = std::isnan(rr_rel_err_max_) ? err : std::max(rr_rel_err_max_, err);
    }
  }
  row.saturated = rec.law.speed_saturated || rec.law.flux_saturated || rec.law.voltage_limited ||
                  rec.voltage_clipped;
  row.limited = static_cast<int>(rec.limited);
  row.stop = static_cast<int>(rec.stop);
  row.brake_line_engaged = rec.brake_engaged;
  row.brake_engaged = board.brake_engaged();

  // The ripple of the previous sample, now that its successor is known. For alpha-beta
  // components the mean square over three phases is half of |x|^2.
  const Vec2 i_now(row.i_alpha_A, row.i_beta_A), v_now(row.v_alpha_V, row.v_beta_V);
  if (rows_seen_ >= 2 && t_s > run_.settle_s) {
    const Vec2 ri = (i_now - 2.0 * i_last_[0] + i_last_[1]) / 4.0;
    const Vec2 rv = (v_now - 2.0 * v_last_[0] + v_last_[1]) / 4.0;
    ripple_i_sq_ += ri.squaredNorm() / 2.0;
    ripple_v_sq_ += rv.squaredNorm() / 2.0;
    ++ripple_count_;
  }
  if (board.config().switching_inverter && t_s > run_.settle_s) {
    pwm_ripple_sq_ += board.plant().period_ripple_sq_A2() / 2.0;
    ++pwm_ripple_count_;
  }
  i_last_[1] = i_last_[0];
  i_last_[0] = i_now;
  v_last_[1] = v_last_[0];
  v_last_[0] = v_now;
  ++rows_seen_;

  const bool running = rec.state == firmware::DriveState::running;
  if (running_from_s_ < 0 && running) running_from_s_ = t_s;
  // The command for this step was recorded command_lead_ticks ago, by a running tick.
  running_ticks_ = running ? running_ticks_ + 1 : 0;
  const int lead = run_.command_lead_ticks;
  const uint64_t n = rows_seen_ - 1;  // this tick's row
  if (t_s > run_.settle_s && lead >= 1 && lead <= 2 && running_ticks_ > uint64_t(lead)) {
    const double err = row.omega_mech_rad_s - commands_[(n + 3 - uint64_t(lead)) % 3];
    command_sq_ += err * err;
    ++command_count_;
  }
  commands_[n % 3] = row.omega_ref_cmd_rad_s;
  // Over CAN the drive is stopped and started at the host's will: only running ticks count.
  metrics_.add({t_s, !run_.commands_over_can || running, row.omega_mech_rad_s - row.omega_ref_rad_s,
                run_.current_fed_law ? row.stator_flux2_Wb2 - row.stator_flux2_ref_Wb2
                                     : row.flux2_Wb2 - row.flux2_ref_Wb2,
                row.load_est_Nm - row.load_Nm, truth.i_s_alphabeta_A.norm(), row.saturated});
  return row;
}

template <typename T>
void TickObserver<T>::observe_current_fed(double t_s, const Vec2& flux_s_AB, const Vec2& i_AB,
                                          const firmware::TickRecord<T>& rec) noexcept {
  SimRow& row = row_;
  row.iol_boundary = rec.law.iol_boundary;
  if (rec.law.iol_boundary) {
    // y2 of (20) from the true stator fluxes of this and the last boundary.
    held_y2_ = flux_s_AB.dot(boundary_flux_s_) - run_.flux_decay * boundary_flux_s_.squaredNorm();
    boundary_flux_s_ = flux_s_AB;
    if (std::isfinite(pending_torque_cmd_) && t_s > run_.settle_s) {
      torque_sq_ += (row.torque_Nm - pending_torque_cmd_) * (row.torque_Nm - pending_torque_cmd_);
      ++torque_count_;
    }
    pending_torque_cmd_ = rec.law.torque_cmd_Nm;
    held_torque_ref_Nm_ = rec.law.torque_ref_Nm;
    held_y2_ref_ = rec.law.y2_ref;
  }
  // How far the stator current departs from the rotor-frame zero-order hold paper 001
  // assumes: the current at the start of the period (after any step) against the current the
  // law takes as held over it.
  const bool iol = run_.current_fed_law;
  row.i_hold_err_A = iol && rec.state == firmware::DriveState::running
                         ? (i_AB - rec.law.i_held_AB_A.template cast<double>()).norm()
                         : 0.0;
  if (iol && t_s > run_.settle_s) {
    hold_sq_ += row.i_hold_err_A * row.i_hold_err_A;
    ++hold_count_;
  }
  row.y2 = held_y2_;
  row.y2_ref = held_y2_ref_;
  row.torque_ref_Nm = held_torque_ref_Nm_;
}

}  // namespace imd::sim
