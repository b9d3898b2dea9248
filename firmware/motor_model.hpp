#pragma once
/// Everything of the drive that is computed from the motor parameters: the exact discretization
/// at the sample period, the observers on it, the prediction over the PWM latency, the laws, the
/// magnetizer, the input limits, the modulator's inner feedback and the checks that need the
/// motion model. It is built whole from one record, outside the tick (at construction, or by
/// Drive::service after a parameter write), and the tick uses it only while it is complete.
/// Building it costs the structured exponentials of the discretization and the laws' designs: far
/// more than a tick, which is why it is never done in one. The discretization runs in T, float on
/// the MCU (control/float_discretization.cpp: about 8 000 instructions there). While the drive
/// runs, a model on a new rotor resistance replaces it at a tick boundary and takes over its state
/// (continue_from), so that the tracked Rr reaches every part (docs/robustness.md).
#include "control/motor_parameters.hpp"
#include "control/real.hpp"
#include "control/rotor_resistance_mras.hpp"
#include "control/voltage_fed_model.hpp"
#include "firmware/drive_config.hpp"
#include "firmware/laws/law_registry.hpp"
#include "firmware/protection/protection.hpp"
#include "firmware/stages/dc_brake.hpp"
#include "firmware/stages/estimate.hpp"
#include "firmware/stages/input_limits.hpp"
#include "firmware/stages/latency_predictor.hpp"
#include "firmware/stages/magnetizer.hpp"
#include "firmware/stages/svpwm_stage.hpp"
#include "hal/pwm.hpp"

namespace imd::firmware {

/// The board quantities the model's parts need besides the motor.
struct BoardScales {
  hal::Pwm& pwm;
  Real encoder_counts_per_rev;
  Real adc_A_per_code;
};

/// The rotor-resistance tracker's settings from the drive's.
inline control::RotorResistanceMrasConfig mras_config(const DriveConfig& config) noexcept {
  control::RotorResistanceMrasConfig c;
  c.sample_period_s = config.sample_period_s;
  c.convergence_time_constant_s = config.rr_convergence_time_constant_s;
  return c;
}

template <typename T>
struct MotorModel {
  /// `nominal_Rr_Ohm`: the motor record's rotor resistance, which bounds the tracked one (0:
  /// m's own).
  MotorModel(const control::MotorParameters& m, const DriveConfig& config, const BoardScales& board,
             Real nominal_Rr_Ohm = 0.0)
      : motor(m),
        coefficients(control::discretize_voltage_fed<T>(m, config.sample_period_s)),
        observers(coefficients, Real(m.pole_pairs), config.encoder_observer_bandwidth_rad_s),
        predictor(coefficients, config.pwm_latency_ticks, config.compensate_latency),
        laws(LawContext{m, config, coefficients}),
        magnetizer(m, coefficients, config),
        limits(m, coefficients,
               {config.voltage_limited, config.modulation_margin, config.i_max_A,
                config.current_margin}),
        svpwm(board.pwm, m, config.sample_period_s,
              {config.compensate_dead_time, config.dead_time_s, config.sample_period_s,
               control::derive_voltage_fed(m).sigma_H}),
        checks(m, coefficients, config, board.encoder_counts_per_rev, board.adc_A_per_code),
        dc_brake(m, config),
        rotor_resistance(m, mras_config(config), nominal_Rr_Ohm > 0 ? nominal_Rr_Ohm : m.Rr_Ohm) {}
  MotorModel(const MotorModel&) = delete;
  MotorModel& operator=(const MotorModel&) = delete;

  /// Takes over every part's state from `old`, the model of the same motor but for its rotor
  /// resistance, which this one replaces from this tick on. Tick context.
  void continue_from(const MotorModel& old) noexcept {
    observers.continue_from(old.observers);
    predictor.continue_from(old.predictor);
    laws.continue_from(old.laws);
    checks.continue_from(old.checks);
    rotor_resistance.continue_from(old.rotor_resistance);
  }

  control::MotorParameters motor;
  control::VoltageFedCoefficients coefficients;
  ObserverEstimator<T> observers;
  LatencyPredictor<T> predictor;
  LawRegistry<T> laws;
  Magnetizer<T> magnetizer;
  InputLimits<T> limits;
  SvpwmStage<T> svpwm;
  MotorChecks<T> checks;
  DcBrake<T> dc_brake;
  control::RotorResistanceMras<T> rotor_resistance;
};

}  // namespace imd::firmware
