#pragma once
/// The magnetizing timeout's rule (docs/safety.md), from the rotor time constant. At zero slip
/// under a constant current I along the flux the rotor flux rises as
///   Phi(t) = Lm I (1 - e^{-t/tau_r}),   tau_r = Lr/Rr,
/// and the magnetizer's current sqrt(ref)/Lm (firmware/stages/magnetizer.hpp) takes it to the
/// magnetized fraction f of the squared reference in t_f = tau_r ln(1 / (1 - sqrt f)): 3.7 tau_r
/// at f = 0.95. A stator flux (Ls I at zero slip, of which sigma Ls I at once) gets there
/// sooner, and so does a larger magnetizing current. The drive judges the flux by its estimate,
/// which follows the record's tau_r whatever the rotor's own: the hand-over comes at t_f, or,
/// when something stops the flux (a current capped below the one that holds the reference, a
/// load that turns the rotor, an open phase), never. The timeout allows twice t_f, which leaves
/// room for the current's rise and a voltage limit, and never less than the configured floor.
/// Construction only.
#include <algorithm>
#include <cmath>

#include "control/motor_parameters.hpp"
#include "control/real.hpp"
#include "firmware/drive_config.hpp"

namespace imd::firmware {

/// The time the model's rotor flux takes to reach `magnetized_fraction` of the squared flux
/// reference under the magnetizer's current (above), in seconds.
inline Real magnetizing_time_s(const control::MotorParameters& motor,
                               Real magnetized_fraction) noexcept {
  const Real fraction = std::clamp(magnetized_fraction, Real(0), Real(0.999));
  return Real(motor.Lr_H / motor.Rr_Ohm) * std::log(1 / (1 - std::sqrt(fraction)));
}

/// The magnetizing timeout: twice the magnetizing time, at least config.magnetizing_timeout_s.
inline Real magnetizing_timeout_s(const control::MotorParameters& motor,
                                  const DriveConfig& config) noexcept {
  return std::max(Real(config.magnetizing_timeout_s),
                  2 * magnetizing_time_s(motor, Real(config.magnetized_fraction)));
}

}  // namespace imd::firmware
