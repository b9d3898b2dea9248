#pragma once
/// The inner feedback (2) of paper 000 and the limits the law plans within. The stator voltage
/// is u = sigma p w J (I~ + beta Phi~) + v~ in the rotor frame: the compensation term is what the
/// feedback adds to the law's input v~. The feasible inputs v~ respect the voltage the SVPWM
/// reaches from the measured bus and the current limit (control/input_disk.hpp). Tick context
/// except construction.
#include <cmath>
#include <limits>

#include "control/frames.hpp"
#include "control/input_disk.hpp"
#include "control/motor_parameters.hpp"
#include "control/real.hpp"
#include "control/svpwm.hpp"
#include "control/voltage_fed_model.hpp"
#include "firmware/limitation.hpp"

namespace imd::firmware {

template <typename T>
class InnerFeedback {
 public:
  explicit InnerFeedback(const control::MotorParameters& motor) noexcept
      : sigma_H_(T(control::derive_voltage_fed(motor).sigma_H)),
        beta_per_H_(T(control::derive_voltage_fed(motor).beta_per_H)),
        pole_pairs_(T(motor.pole_pairs)) {}

  /// sigma p w J (I~ + beta Phi~), the part of u that the feedback (2) adds.
  control::Vec2<T> compensation_AB_V(const control::RotorFrameState<T>& x) const noexcept {
    return sigma_H_ * pole_pairs_ * x.omega_mech_rad_s *
           control::J_times<T>(x.i_s_AB_A + beta_per_H_ * x.flux_r_AB_Wb);
  }
  T pole_pairs() const noexcept { return pole_pairs_; }

 private:
  T sigma_H_, beta_per_H_, pole_pairs_;
};

struct InputLimitsConfig {
  bool voltage_limited = true;  ///< false only to reproduce the paper (no limit)
  Real modulation_margin = Real(0.95);
  Real i_max_A = INFINITY;  ///< infinite: no current limit
  Real current_margin = Real(0.95);
};

template <typename T>
class InputLimits {
 public:
  InputLimits(const control::MotorParameters& motor, const control::VoltageFedCoefficients& c,
              const InputLimitsConfig& config) noexcept
      : feedback_(motor),
        voltage_limited_(config.voltage_limited),
        current_limited_(std::isfinite(config.i_max_A)),
        modulation_margin_(T(config.modulation_margin)),
        current_limit_A_(T(config.current_margin * config.i_max_A)),
        a21_(T(c.a21)),
        a22_(T(c.a22)),
        b2_(T(c.b2)) {}

  /// The stator voltage modulus the modulation reaches from this bus (+inf without a limit).
  T v_max_V(T v_bus_V) const noexcept {
    return voltage_limited_ ? modulation_margin_ * control::svpwm_linear_limit_V(v_bus_V)
                            : std::numeric_limits<T>::infinity();
  }

  /// The rotor-frame inputs v~ allowed over the period that starts in state x. Inlined into the
  /// law stage, before the write (docs/performance-compiler.md).
  [[gnu::always_inline]] control::InputDisk<T> feasible(const control::RotorFrameState<T>& x,
                                                        T v_bus_V) const noexcept {
    control::InputDisk<T> voltage, current;
    if (voltage_limited_) {
      voltage = {-feedback_.compensation_AB_V(x), v_max_V(v_bus_V)};
    }
    if (current_limited_) {
      current = {(a21_ * x.flux_r_AB_Wb + a22_ * x.i_s_AB_A) * minus_per_b2_, current_radius_V_};
    }
    return control::inscribed_disk(voltage, current);
  }

  /// Which of the two limits an input v~ on the edge of the feasible set presses against: the
  /// disk it is nearer to leaving, measured as the share of each radius it uses, so that volts
  /// and amperes compare (the inscribed disk touches each only at one point). Not in the tick's
  /// common path: only on ticks where the law reports the input limited.
  Limitation binding(const control::RotorFrameState<T>& x, T v_bus_V,
                     const control::Vec2<T>& v_AB_V) const noexcept {
    if (!current_limited_) return Limitation::voltage;
    if (!voltage_limited_) return Limitation::current;
    const T voltage_share = (v_AB_V + feedback_.compensation_AB_V(x)).norm() / v_max_V(v_bus_V);
    const T current_share =
        (a21_ * x.flux_r_AB_Wb + a22_ * x.i_s_AB_A + b2_ * v_AB_V).norm() / current_limit_A_;
    return current_share > voltage_share ? Limitation::current : Limitation::voltage;
  }

 private:
  InnerFeedback<T> feedback_;
  bool voltage_limited_, current_limited_;
  T modulation_margin_, current_limit_A_, a21_, a22_, b2_;
  T current_radius_V_ = current_limit_A_ / b2_;  ///< the current disk's, once (after b2_)
  T minus_per_b2_ = T(-1) / b2_;  ///< its centre multiplies by it, not divides (after b2_)
};

}  // namespace imd::firmware
