#pragma once
/// Ideal sensors, as paper 000's Section III assumes: the drive sees the plant's true current,
/// speed, position, flux and load. A simulation-only substitute for the drive's sense and
/// estimate stages (firmware::Sensing and firmware::StateEstimator); the bus voltage still
/// comes from the board's ADC. With `section_iv`, the paper's Section IV estimators (the flux
/// observer and the load estimator, on the true speed and current) replace the true flux and
/// load. Tick context except construction.
#include <algorithm>
#include <cmath>

#include "control/flux_observer.hpp"
#include "control/load_estimator.hpp"
#include "control/svpwm.hpp"
#include "firmware/drive_config.hpp"
#include "firmware/stages/estimate.hpp"
#include "firmware/stages/sense.hpp"
#include "hal_sim/sim_board.hpp"

namespace imd::sim {

template <typename T>
class IdealSensors final : public firmware::Sensing<T>, public firmware::StateEstimator<T> {
 public:
  IdealSensors(SimBoard& board, const control::MotorParameters& motor,
               const firmware::DriveConfig& config)
      : board_(board),
        adc_(board.adc(), board.encoder(),
             {config.adc_calibration_ticks, config.adc_offset_limit_A}),
        coefficients_(control::discretize_voltage_fed(motor, config.sample_period_s)),
        flux_(coefficients_),
        load_(coefficients_,
              control::place_load_estimator(coefficients_, config.load_estimator_pole,
                                            config.load_estimator_pole)),
        current_(coefficients_),
        section_iv_(config.section_iv_load_estimator),
        pole_pairs_(T(motor.pole_pairs)) {}

  firmware::Measurement<T> measure(bool calibrating) noexcept override {
    firmware::Measurement<T> m = adc_.measure(calibrating);  // the bus, the calibration
    if (!m.valid) return m;
    read_truth();
    const auto i_abc = control::inverse_clarke(control::Vec2<T>(
        control::Rotation<T>::from_angle(pole_pairs_ * theta_mech_rad_).apply(i_s_AB_A_)));
    m.adc_saturated = false;  // the ADC's currents are not used
    m.i_peak_A = std::max({std::abs(i_abc[0]), std::abs(i_abc[1]), std::abs(i_abc[2])});
    for (int phase = 0; phase < 3; ++phase) m.i_abc_A[phase] = i_abc[phase];
    return m;
  }

  firmware::Estimate<T> estimate(const firmware::Measurement<T>&) noexcept override {
    last_.valid = true;
    last_.x.i_s_AB_A = i_s_AB_A_;
    last_.x.omega_mech_rad_s = omega_mech_rad_s_;
    last_.x.theta_mech_rad = theta_mech_rad_;
    last_.x.flux_r_AB_Wb = section_iv_ ? flux_.flux_r_AB_Wb() : flux_r_AB_Wb_;
    last_.load_Nm = section_iv_ ? load_.load_Nm() : load_Nm_;
    last_.current_predicted = predicted_;
    last_.i_predicted_alphabeta_A =
        control::Rotation<T>::from_angle(pole_pairs_ * theta_mech_rad_).apply(i_next_AB_A_);
    return last_;
  }

  void advance(const control::Vec2<T>& v_acting_AB_V) noexcept override {
    i_next_AB_A_ = current_.next_AB_A(last_.x.flux_r_AB_Wb, last_.x.i_s_AB_A, v_acting_AB_V);
    predicted_ = true;
    flux_.update(last_.x.i_s_AB_A, v_acting_AB_V);
    load_.update(last_.x.omega_mech_rad_s, last_.x.i_s_AB_A, last_.x.flux_r_AB_Wb, v_acting_AB_V);
  }

 private:
  /// The plant's state at the start of this tick, in the rotor frame, rounded to T.
  void read_truth() noexcept {
    const PlantState& s = board_.plant().state();
    const auto rotor =
        control::Rotation<double>::from_angle(board_.plant().pole_pairs() * s.theta_mech_rad);
    const Vec2 flux = rotor.apply_inverse(s.flux_r_alphabeta_Wb);
    const Vec2 current = rotor.apply_inverse(s.i_s_alphabeta_A);
    flux_r_AB_Wb_ = control::Vec2<T>(T(flux.x()), T(flux.y()));
    i_s_AB_A_ = control::Vec2<T>(T(current.x()), T(current.y()));
    omega_mech_rad_s_ = T(s.omega_mech_rad_s);
    theta_mech_rad_ = T(s.theta_mech_rad);
    load_Nm_ = T(board_.load_Nm());
  }

  SimBoard& board_;
  firmware::BoardSensing<T> adc_;
  control::VoltageFedCoefficients coefficients_;
  control::FluxObserver<T> flux_;
  control::LoadEstimator<T> load_;
  firmware::CurrentPredictor<T> current_;
  bool section_iv_;
  T pole_pairs_;
  control::Vec2<T> flux_r_AB_Wb_ = control::Vec2<T>::Zero(), i_s_AB_A_ = control::Vec2<T>::Zero();
  T omega_mech_rad_s_ = T(0), theta_mech_rad_ = T(0), load_Nm_ = T(0);
  firmware::Estimate<T> last_;
  control::Vec2<T> i_next_AB_A_ = control::Vec2<T>::Zero();  ///< predicted for the next tick
  bool predicted_ = false;
};

}  // namespace imd::sim
