#pragma once
/// What one tick measured, estimated and commanded: the source of telemetry and of the
/// simulation's CSV. Plain data, copied once per tick. T is the drive's arithmetic (float on
/// the MCU, so that the tick converts nothing).
#include <cstdint>

#include "firmware/drive_state.hpp"

namespace imd::firmware {

template <typename T>
struct TickRecord {
  uint64_t tick = 0;
  DriveState state = DriveState::calibrating;
  FaultCode fault = FaultCode::none;  ///< the first latched fault
  uint16_t fault_bits = 0;            ///< every latched fault, bit n = code n
  // Estimates (rotor frame) at this tick.
  T omega_est_rad_s = T(0), theta_est_rad = T(0), flux2_est_Wb2 = T(0), load_est_Nm = T(0);
  T flux_est_A_Wb = T(0), flux_est_B_Wb = T(0);
  T i_alpha_A = T(0), i_beta_A = T(0), v_bus_V = T(0);
  T iA_A = T(0), iB_A = T(0);  ///< estimated stator current, rotor frame
  // References the law aimed at (for the step the input acts on).
  T omega_ref_rad_s = T(0), flux2_ref_Wb2 = T(0);
  /// The flux the selected controller regulates: rotor flux (dsmc) or stator flux (iol).
  T controlled_flux2_Wb2 = T(0), controlled_flux2_ref_Wb2 = T(0);
  // Command.
  T v_A_V = T(0), v_B_V = T(0);         ///< v~ applied (after limiting)
  T u_alpha_V = T(0), u_beta_V = T(0);  ///< stator voltage command
  T discriminant = T(0), c_k = T(0), det_B = T(0);
  // The current-fed controller (iol), at its last T0 boundary.
  T torque_ref_Nm = T(0), torque_cmd_Nm = T(0), y2 = T(0), y2_ref = T(0);
  T stator_flux2_est_Wb2 = T(0);
  T iA_cmd_A = T(0), iB_cmd_A = T(0);    ///< rotor-frame current command
  T iA_held_A = T(0), iB_held_A = T(0);  ///< iol: the current the law assumes held now
  bool torque_limited = false;
  bool iol_boundary = false;  ///< the IOL law ran this tick
  bool speed_saturated = false, flux_saturated = false, voltage_clipped = false;
  uint32_t exec_ns = 0;
};

}  // namespace imd::firmware
