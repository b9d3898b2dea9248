#pragma once
/// Everything of the drive that is computed from the motor parameters: the exact discretization
/// at the sample period, the observers on it, the prediction over the PWM latency, the laws, the
/// magnetizer, the input limits, the modulator's inner feedback and the checks that need the
/// motion model. It is built whole from one record, outside the tick (at construction, or by
/// Drive::service after a parameter write), and the tick uses it only while it is complete.
/// Building it costs the matrix exponential of the discretization and the laws' designs: far
/// more than a tick, which is why it is never done in one.
#include "control/motor_parameters.hpp"
#include "control/voltage_fed_model.hpp"
#include "firmware/drive_config.hpp"
#include "firmware/laws/law_registry.hpp"
#include "firmware/protection/protection.hpp"
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
  double encoder_counts_per_rev;
  double adc_A_per_code;
};

template <typename T>
struct MotorModel {
  MotorModel(const control::MotorParameters& m, const DriveConfig& config,
             const BoardScales& board)
      : motor(m),
        coefficients(control::discretize_voltage_fed(m, config.sample_period_s)),
        observers(coefficients, m.pole_pairs, config.encoder_observer_bandwidth_rad_s),
        predictor(coefficients, config.pwm_latency_ticks, config.compensate_latency),
        laws(LawContext{m, config, coefficients}),
        magnetizer(m, coefficients, config),
        limits(m, coefficients,
               {config.voltage_limited, config.modulation_margin, config.i_max_A,
                config.current_margin}),
        svpwm(board.pwm, m, config.sample_period_s,
              {config.compensate_dead_time, config.dead_time_s, config.sample_period_s,
               control::derive_voltage_fed(m).sigma_H}),
        checks(m, coefficients, config, board.encoder_counts_per_rev, board.adc_A_per_code) {}
  MotorModel(const MotorModel&) = delete;
  MotorModel& operator=(const MotorModel&) = delete;

  control::MotorParameters motor;
  control::VoltageFedCoefficients coefficients;
  ObserverEstimator<T> observers;
  LatencyPredictor<T> predictor;
  LawRegistry<T> laws;
  Magnetizer<T> magnetizer;
  InputLimits<T> limits;
  SvpwmStage<T> svpwm;
  MotorChecks<T> checks;
};

}  // namespace imd::firmware
