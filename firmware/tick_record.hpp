#pragma once
/// What one tick measured, estimated and commanded: the source of telemetry and of the
/// simulation's CSV. Plain data, copied once per tick. T is the drive's arithmetic (float on
/// the MCU, so that the tick converts nothing). The rotor-aligned frame is AB.
#include <cstdint>

#include "control/frames.hpp"
#include "firmware/drive_state.hpp"
#include "firmware/laws/control_law.hpp"
#include "firmware/protection/stop_category.hpp"
#include "firmware/stages/stage_clock.hpp"

namespace imd::firmware {

template <typename T>
struct TickRecord {
  using Vec2 = control::Vec2<T>;

  uint64_t tick = 0;
  DriveState state = DriveState::calibrating;
  FaultCode fault = FaultCode::none;  ///< the first latched fault
  uint16_t fault_bits = 0;            ///< every latched fault, bit n = code n
  // Measured.
  Vec2 i_alphabeta_A = Vec2::Zero();
  T v_bus_V = T(0);
  // Estimates (rotor frame) at this tick.
  T omega_est_rad_s = T(0), theta_est_rad = T(0), flux2_est_Wb2 = T(0), load_est_Nm = T(0);
  Vec2 flux_est_AB_Wb = Vec2::Zero();
  Vec2 i_s_est_AB_A = Vec2::Zero();  ///< stator current
  T rr_est_Ohm = T(0);     ///< the tracked rotor resistance (the model's when not tracking)
  T rr_scale = T(0);       ///< rr_est_Ohm over the motor record's
  bool rr_adapting = false;  ///< the tracker moved the estimate this tick (excited)
  // References the law aimed at (for the step the input acts on).
  T omega_ref_rad_s = T(0), flux2_ref_Wb2 = T(0);
  /// The flux the selected law regulates: rotor flux (dsmc) or stator flux (iol).
  T controlled_flux2_Wb2 = T(0), controlled_flux2_ref_Wb2 = T(0);
  // Command.
  Vec2 v_AB_V = Vec2::Zero();         ///< v~ applied (after limiting; zero with the PWM off)
  Vec2 u_alphabeta_V = Vec2::Zero();  ///< stator voltage command
  Vec2 i_cmd_AB_A = Vec2::Zero();     ///< current command (magnetizing, current-fed law)
  bool voltage_clipped = false;
  LawDiagnostics<T> law;
  Limitation limited = Limitation::none;  ///< held for the monitor's window (limitation.hpp)
  StopCategory stop = StopCategory::none;  ///< the latched fault's stop
  bool brake_engaged = true;               ///< the holding brake line not driven
  // Execution time: the tick up to the PWM write, and each stage in execution-clock counts,
  // measured on the ticks with stages_timed (publish's only after the record was sent).
  uint32_t exec_ns = 0;
  bool stages_timed = false;
  StageCounts stage_counts{};
};

}  // namespace imd::firmware
