#pragma once
/// Runs a scenario: the drive firmware on the simulated board, in lock-step, and the metrics
/// of docs/scenarios.md. Shared by drive_sim and the sim-tier tests.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "hal_sim/scenario.hpp"

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
  bool iol_boundary = false;
  int state = 0;
  bool saturated = false;
};

struct FaultEvent {
  std::string code;
  double detected_at_s = 0.0;
};

/// Metrics over t > settle_s from the plant's true state (i_peak_total_A: the whole run). NaN
/// when the run ended before settle_s.
struct Summary {
  double speed_rms_err_rad_s = 0.0, speed_max_err_rad_s = 0.0;
  double flux2_rms_err_Wb2 = 0.0, flux2_max_err_Wb2 = 0.0;
  double load_est_rms_err_Nm = 0.0;
  double torque_rms_err_Nm = 0.0;  ///< iol: torque against the law's command one T0 earlier
  double i_hold_rms_err_A = 0.0;   ///< iol: RMS of |i_AB - i_cmd| over the ticks
  double i_peak_A = 0.0, i_peak_total_A = 0.0;
  double saturated_fraction = 0.0;
  uint64_t ticks = 0;
  double simulated_s = 0.0, wall_time_s = 0.0;
  double tick_exec_ns_mean = 0.0, tick_exec_ns_max = 0.0;
  double running_from_s = -1.0;  ///< first time the drive was running (-1: never)
  std::vector<FaultEvent> faults;
};

struct RunCallbacks {
  std::function<void(const SimRow&)> row;  ///< every tick, if set
  /// About once per wall-clock second: simulated time so far.
  std::function<void(double simulated_s, double wall_s)> progress;
};

Summary run_scenario(const Scenario& scenario, const RunCallbacks& callbacks = {});

}  // namespace imd::sim
