#pragma once
/// What one tick measured, estimated and commanded: the source of telemetry and of the
/// simulation's CSV. Plain data, copied once per tick.
#include <cstdint>

#include "firmware/drive_state.hpp"

namespace imd::firmware {

struct TickRecord {
  uint64_t tick = 0;
  DriveState state = DriveState::calibrating;
  FaultCode fault = FaultCode::none;  ///< the first latched fault
  uint16_t fault_bits = 0;            ///< every latched fault, bit n = code n
  // Estimates (rotor frame) at this tick.
  double omega_est_rad_s = 0.0, theta_est_rad = 0.0, flux2_est_Wb2 = 0.0, load_est_Nm = 0.0;
  double flux_est_A_Wb = 0.0, flux_est_B_Wb = 0.0;
  double i_alpha_A = 0.0, i_beta_A = 0.0, v_bus_V = 0.0;
  double i_A_A = 0.0, i_B_A = 0.0;  ///< estimated stator current, rotor frame
  // References the law aimed at (for the step the input acts on).
  double omega_ref_rad_s = 0.0, flux2_ref_Wb2 = 0.0;
  /// The flux the selected controller regulates: rotor flux (dsmc) or stator flux (iol).
  double controlled_flux2_Wb2 = 0.0, controlled_flux2_ref_Wb2 = 0.0;
  // Command.
  double v_A_V = 0.0, v_B_V = 0.0;         ///< v~ applied (after limiting)
  double u_alpha_V = 0.0, u_beta_V = 0.0;  ///< stator voltage command
  double discriminant = 0.0, c_k = 0.0, det_B = 0.0;
  // The current-fed controller (iol), at its last T0 boundary.
  double torque_ref_Nm = 0.0, torque_cmd_Nm = 0.0, y2 = 0.0, y2_ref = 0.0;
  double stator_flux2_est_Wb2 = 0.0;
  double i_cmd_A_A = 0.0, i_cmd_B_A = 0.0;    ///< rotor-frame current command
  double i_held_A_A = 0.0, i_held_B_A = 0.0;  ///< iol: the current the law assumes held now
  bool torque_limited = false;
  bool iol_boundary = false;  ///< the IOL law ran this tick
  bool speed_saturated = false, flux_saturated = false, voltage_clipped = false;
  uint32_t exec_ns = 0;
};

}  // namespace imd::firmware
