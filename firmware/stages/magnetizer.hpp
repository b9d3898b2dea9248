#pragma once
/// The magnetizing start-up, which the supervisor runs before any law: B_k is singular at zero
/// flux, so the motor is first magnetized at zero slip by a current along the flux (the A axis
/// while there is none), through the deadbeat current loop. Steady state at zero slip:
/// Phi_r = Lm I and phi_s = Ls I, so the current that holds the flux reference is sqrt(ref)/Lm
/// for a rotor-flux law and sqrt(ref)/Ls for a stator-flux law. Tick context except
/// construction.
#include <algorithm>
#include <cmath>

#include "control/deadbeat_current.hpp"
#include "control/motor_parameters.hpp"
#include "firmware/drive_config.hpp"
#include "firmware/laws/control_law.hpp"

namespace imd::firmware {

template <typename T>
class Magnetizer {
 public:
  Magnetizer(const control::MotorParameters& motor, const control::VoltageFedCoefficients& c,
             const DriveConfig& config) noexcept
      : current_loop_(c),
        current_A_(T(config.magnetizing_current_A)),
        current_max_A_(T(Real(0.9) * config.i_max_A)),
        current_limited_(std::isfinite(config.i_max_A)),
        magnetized_fraction_(T(config.magnetized_fraction)),
        Lm_H_(T(motor.Lm_H)),
        Ls_H_(T(motor.Ls_H)),
        sigma_H_(T(control::derive_voltage_fed(motor).sigma_H)),
        Lm_over_Lr_(T(motor.Lm_H / motor.Lr_H)) {}

  /// The squared modulus of the flux `kind` in state x.
  T flux2_Wb2(const control::RotorFrameState<T>& x, ControlledFlux kind) const noexcept {
    if (kind == ControlledFlux::rotor) return x.flux_r_AB_Wb.squaredNorm();
    return (sigma_H_ * x.i_s_AB_A + Lm_over_Lr_ * x.flux_r_AB_Wb).squaredNorm();
  }
  static T flux2_ref_Wb2(const Reference<T>& ref, ControlledFlux kind) noexcept {
    return kind == ControlledFlux::stator ? ref.stator_flux2_Wb2 : ref.flux2_Wb2;
  }
  /// The flux has reached the share of its reference at which the law takes over.
  bool magnetized(const control::RotorFrameState<T>& x, const Reference<T>& ref,
                  ControlledFlux kind) const noexcept {
    return flux2_Wb2(x, kind) >= magnetized_fraction_ * flux2_ref_Wb2(ref, kind);
  }

  /// The magnetizing current in state x (capped at 0.9 i_max).
  control::Vec2<T> current_AB_A(const control::RotorFrameState<T>& x, const Reference<T>& ref,
                                ControlledFlux kind) const noexcept {
    T current_A = current_A_;
    if (!(current_A > T(0))) {
      current_A = kind == ControlledFlux::stator
                      ? std::sqrt(std::max(ref.stator_flux2_Wb2, T(0))) / Ls_H_
                      : std::sqrt(std::max(ref.flux2_Wb2, T(0))) / Lm_H_;
    }
    if (current_limited_) current_A = std::min(current_A, current_max_A_);
    const T flux = x.flux_r_AB_Wb.norm();
    const control::Vec2<T> direction =
        flux > T(1e-3) ? control::Vec2<T>(x.flux_r_AB_Wb / flux) : control::Vec2<T>(T(1), T(0));
    return current_A * direction;
  }

  /// The law stage's output while magnetizing: the current, and the input that reaches it.
  LawOutput<T> step(const control::RotorFrameState<T>& x_input, const Reference<T>& ref,
                    ControlledFlux kind, const control::InputDisk<T>& feasible) const noexcept {
    LawOutput<T> out;
    out.i_cmd_AB_A = current_AB_A(x_input, ref, kind);
    out.v_AB_V =
        current_loop_.input(x_input.flux_r_AB_Wb, x_input.i_s_AB_A, out.i_cmd_AB_A, feasible);
    return out;
  }

 private:
  control::DeadbeatCurrent<T> current_loop_;
  T current_A_, current_max_A_;
  bool current_limited_;
  T magnetized_fraction_, Lm_H_, Ls_H_, sigma_H_, Lm_over_Lr_;
};

}  // namespace imd::firmware
